#include "estimator/eval/trajectory_format.h"

#include <array>
#include <fstream>
#include <vector>

#include "estimator/eval/csv_trajectory.h"
#include "estimator/eval/eval_error.h"
#include "estimator/eval/text_table_reader.h"

namespace rover::eval {
namespace {

constexpr std::array<std::pair<TrajectoryFormat, std::string_view>, 5> kNames = {{
    {TrajectoryFormat::kAuto, "auto"},
    {TrajectoryFormat::kTum, "tum"},
    {TrajectoryFormat::kEuroc, "euroc"},
    {TrajectoryFormat::kOpenVins, "openvins"},
    {TrajectoryFormat::kMcap, "mcap"},
}};

bool StartsWithMcapMagic(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char magic[8] = {};
  in.read(magic, sizeof magic);
  return in.gcount() == 8 && std::string_view(magic, 8) == std::string_view("\x89MCAP0\r\n", 8);
}

}  // namespace

std::string_view ToString(TrajectoryFormat format) {
  for (const auto& [f, name] : kNames) {
    if (f == format) return name;
  }
  return "unknown";
}

std::optional<TrajectoryFormat> ParseTrajectoryFormat(std::string_view name) {
  for (const auto& [f, n] : kNames) {
    if (n == name) return f;
  }
  return std::nullopt;
}

TrajectoryFormat DetectTrajectoryFormat(const std::string& path) {
  if (!std::ifstream(path)) throw EvalError(path + ": cannot open (no such file or not readable)");
  if (StartsWithMcapMagic(path)) return TrajectoryFormat::kMcap;
  if (path.size() >= 5 && path.substr(path.size() - 5) == ".mcap") return TrajectoryFormat::kMcap;

  // The first data line decides between CSV and TUM; the header (the first
  // comment or non-numeric line before it) between the CSV layouts.
  TextTableReader reader(path, TextTableReader::Separator::kComma);
  std::vector<std::string_view> cells;
  std::vector<std::string> header;
  bool have_header = false;
  bool have_data = false;
  bool commas = false;
  while (reader.Next(&cells, /*comments=*/true)) {
    const char first = cells[0].empty() ? ' ' : cells[0].front();
    const bool numeric = (first >= '0' && first <= '9') || first == '-' || first == '.';
    if (reader.is_comment() || !numeric) {
      if (!have_header) header.assign(cells.begin(), cells.end());
      have_header = true;
      continue;
    }
    have_data = true;
    commas = cells.size() > 1;
    break;
  }
  if (!have_header && !have_data) {
    throw EvalError(path + ": expected a trajectory, found an empty file");
  }
  if (!have_data) commas = header.size() > 1;  // The reader will report the missing rows.
  if (!commas) return TrajectoryFormat::kTum;
  if (have_header) {
    const std::vector<std::string_view> names(header.begin(), header.end());
    if (IsEurocHeader(names)) return TrajectoryFormat::kEuroc;
    if (CsvLayoutFromHeader(names)) return TrajectoryFormat::kOpenVins;
  }
  return TrajectoryFormat::kEuroc;
}

}  // namespace rover::eval
