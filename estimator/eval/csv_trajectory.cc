#include "estimator/eval/csv_trajectory.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <initializer_list>

#include "estimator/eval/eval_error.h"
#include "estimator/eval/number_format.h"
#include "estimator/eval/text_table_reader.h"

namespace rover::eval {
namespace {

// A header cell reduced to lowercase letters and digits, with its unit (the
// text inside [] or (), if any) kept apart.
struct ColumnName {
  std::string name;
  std::string unit;
};

ColumnName Normalize(std::string_view cell) {
  ColumnName out;
  int depth = 0;
  for (const char raw : cell) {
    const char c = static_cast<char>(std::tolower(static_cast<unsigned char>(raw)));
    if (c == '[' || c == '(') {
      ++depth;
      continue;
    }
    if (c == ']' || c == ')') {
      depth = std::max(0, depth - 1);
      continue;
    }
    if (c == ' ' || c == '_' || c == '-' || c == '#') continue;
    (depth > 0 ? out.unit : out.name) += c;
  }
  return out;
}

bool OneOf(const std::string& s, std::initializer_list<std::string_view> options) {
  return std::find(options.begin(), options.end(), s) != options.end();
}

// Column of an axis-named quantity ("px", "p_RS_R_x", ...), or npos.
std::size_t FindAxis(const std::vector<ColumnName>& names,
                     std::initializer_list<std::string_view> prefixes, char axis) {
  for (std::size_t i = 0; i < names.size(); ++i) {
    const std::string& n = names[i].name;
    if (n.empty() || n.back() != axis) continue;
    if (OneOf(n.substr(0, n.size() - 1), prefixes)) return i;
  }
  return std::string::npos;
}

bool LooksLikeNumber(std::string_view cell) {
  if (cell.empty()) return false;
  const char c = cell.front();
  return (c >= '0' && c <= '9') || c == '-' || c == '+' || c == '.';
}

std::string Joined(const std::vector<std::string_view>& cells) {
  std::string s;
  for (std::size_t i = 0; i < cells.size(); ++i) s += (i ? "," : "") + std::string(cells[i]);
  return s;
}

// Reads one data row of `layout` into a sample appended to *trajectory.
void ReadRow(const TextTableReader& reader, const std::vector<std::string_view>& cells,
             const CsvLayout& layout, Trajectory* trajectory) {
  if (cells.size() < layout.MinColumns()) {
    reader.Fail("expected at least " + std::to_string(layout.MinColumns()) +
                " comma-separated columns, found " + std::to_string(cells.size()));
  }
  PoseSample s;
  const std::string_view t = cells[layout.time];
  bool seconds = layout.time_unit == CsvLayout::TimeUnit::kSeconds;
  if (layout.time_unit == CsvLayout::TimeUnit::kUnknown) {
    seconds = t.find_first_of(".eE") != std::string_view::npos;
  }
  s.stamp = seconds ? reader.Seconds(t, "the timestamp [s]")
                    : reader.Nanoseconds(t, "the timestamp [ns]");
  static constexpr const char* kAxes[] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    s.p_world_body[i] = reader.Double(cells[layout.position[static_cast<std::size_t>(i)]],
                                      std::string("position ") + kAxes[i]);
  }
  const double w = reader.Double(cells[layout.quaternion_wxyz[0]], "quaternion w");
  const double x = reader.Double(cells[layout.quaternion_wxyz[1]], "quaternion x");
  const double y = reader.Double(cells[layout.quaternion_wxyz[2]], "quaternion y");
  const double z = reader.Double(cells[layout.quaternion_wxyz[3]], "quaternion z");
  s.q_world_body = Eigen::Quaterniond(w, x, y, z);
  const double norm = s.q_world_body.norm();
  if (std::abs(norm - 1.0) > 1e-3) {
    reader.Fail("expected a unit quaternion (norm 1 +- 1e-3), found norm " + FormatDouble(norm));
  }
  s.q_world_body = UnitQuaternion(s.q_world_body);
  if (layout.velocity) {
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) {
      v[i] = reader.Double(cells[(*layout.velocity)[static_cast<std::size_t>(i)]],
                           std::string("velocity ") + kAxes[i]);
    }
    s.v_world_body_m_s = v;
  }
  if (!trajectory->empty() && s.stamp <= trajectory->samples().back().stamp) {
    reader.Fail("expected the timestamp to increase, found " + s.stamp.ToString() + " after " +
                trajectory->samples().back().stamp.ToString());
  }
  trajectory->Append(s);
}

void WriteNumber(std::ofstream& out, double value) { out << FormatDouble(value); }

}  // namespace

std::size_t CsvLayout::MinColumns() const {
  std::size_t n = time;
  for (const std::size_t c : position) n = std::max(n, c);
  for (const std::size_t c : quaternion_wxyz) n = std::max(n, c);
  if (velocity) {
    for (const std::size_t c : *velocity) n = std::max(n, c);
  }
  return n + 1;
}

CsvLayout EurocCsvLayout() { return CsvLayout{}; }

std::optional<CsvLayout> CsvLayoutFromHeader(const std::vector<std::string_view>& cells,
                                             std::string* problem) {
  std::vector<ColumnName> names;
  for (const std::string_view c : cells) names.push_back(Normalize(c));
  auto fail = [&](const std::string& why) -> std::optional<CsvLayout> {
    if (problem != nullptr) *problem = why;
    return std::nullopt;
  };

  CsvLayout layout;
  std::size_t time = std::string::npos;
  for (std::size_t i = 0; i < names.size() && time == std::string::npos; ++i) {
    const std::string& n = names[i].name;
    for (const std::string_view base : {"timestamp", "time", "t", "stamp"}) {
      const std::string b(base);
      if (n == b) {
        time = i;
        const std::string& u = names[i].unit;
        layout.time_unit = u == "ns"                  ? CsvLayout::TimeUnit::kNanoseconds
                           : (u == "s" || u == "sec") ? CsvLayout::TimeUnit::kSeconds
                                                      : CsvLayout::TimeUnit::kUnknown;
        break;
      }
      if (n == b + "ns" || n == b + "nsec") {
        time = i;
        layout.time_unit = CsvLayout::TimeUnit::kNanoseconds;
        break;
      }
      if (n == b + "s" || n == b + "sec") {
        time = i;
        layout.time_unit = CsvLayout::TimeUnit::kSeconds;
        break;
      }
    }
  }
  if (time == std::string::npos) return fail("no time column (timestamp, time, t, stamp)");
  layout.time = time;

  const auto position_prefixes = {std::string_view("p"),        std::string_view("t"),
                                  std::string_view(""),         std::string_view("pos"),
                                  std::string_view("position"), std::string_view("prsr"),
                                  std::string_view("prs")};
  const auto quaternion_prefixes = {std::string_view("q"), std::string_view("qrs"),
                                    std::string_view("quat"), std::string_view("orientation"),
                                    std::string_view("rot")};
  const auto velocity_prefixes = {std::string_view("v"), std::string_view("vrsr"),
                                  std::string_view("vrs"), std::string_view("vel"),
                                  std::string_view("velocity")};
  const char axes[] = {'x', 'y', 'z'};
  for (std::size_t i = 0; i < 3; ++i) {
    const std::size_t p = FindAxis(names, position_prefixes, axes[i]);
    if (p == std::string::npos) return fail(std::string("no position ") + axes[i] + " column");
    layout.position[i] = p;
  }
  const char q_axes[] = {'w', 'x', 'y', 'z'};
  for (std::size_t i = 0; i < 4; ++i) {
    const std::size_t q = FindAxis(names, quaternion_prefixes, q_axes[i]);
    if (q == std::string::npos) return fail(std::string("no quaternion ") + q_axes[i] + " column");
    layout.quaternion_wxyz[i] = q;
  }
  std::array<std::size_t, 3> v{};
  bool has_velocity = true;
  for (std::size_t i = 0; i < 3; ++i) {
    v[i] = FindAxis(names, velocity_prefixes, axes[i]);
    has_velocity = has_velocity && v[i] != std::string::npos;
  }
  if (has_velocity) layout.velocity = v;
  return layout;
}

bool IsEurocHeader(const std::vector<std::string_view>& cells) {
  if (cells.size() < 8) return false;
  return Normalize(cells[1]).name == "prsrx" && Normalize(cells[4]).name == "qrsw";
}

Trajectory ReadEurocCsvTrajectory(const std::string& path) {
  TextTableReader reader(path, TextTableReader::Separator::kComma);
  Trajectory trajectory;
  trajectory.set_source(path);
  CsvLayout layout = EurocCsvLayout();
  bool header_seen = false;
  bool first_row = true;
  std::vector<std::string_view> cells;
  while (reader.Next(&cells, /*comments=*/true)) {
    const bool header = reader.is_comment() || !LooksLikeNumber(cells[0]);
    if (header) {
      if (!trajectory.empty() || header_seen) {
        if (!reader.is_comment()) {
          reader.Fail("expected a data row (timestamp [ns], p, q), found '" +
                      std::string(reader.line()) + "'");
        }
        continue;
      }
      header_seen = true;
      const std::optional<CsvLayout> named = CsvLayoutFromHeader(cells);
      if (named) {
        CsvLayout fixed = *named;
        fixed.velocity.reset();
        CsvLayout expected = EurocCsvLayout();
        expected.time_unit = fixed.time_unit == CsvLayout::TimeUnit::kUnknown
                                 ? CsvLayout::TimeUnit::kUnknown
                                 : CsvLayout::TimeUnit::kNanoseconds;
        if (!(fixed == expected)) {
          reader.Fail(
              "expected EuRoC columns (timestamp [ns], p x y z, q w x y z), found the header '" +
              Joined(cells) + "' (use the openvins format for other column layouts)");
        }
        if (named->velocity == std::array<std::size_t, 3>{8, 9, 10}) {
          layout.velocity = named->velocity;
        }
      }
      continue;
    }
    if (first_row && !header_seen && cells.size() >= 11) {
      layout.velocity = std::array<std::size_t, 3>{8, 9, 10};
    }
    first_row = false;
    ReadRow(reader, cells, layout, &trajectory);
  }
  if (trajectory.empty()) throw EvalError(path + ": expected trajectory rows, found none");
  return trajectory;
}

Trajectory ReadOpenVinsCsvTrajectory(const std::string& path) {
  TextTableReader reader(path, TextTableReader::Separator::kComma);
  Trajectory trajectory;
  trajectory.set_source(path);
  std::optional<CsvLayout> layout;
  std::vector<std::string_view> cells;
  while (reader.Next(&cells, /*comments=*/true)) {
    if (!layout) {
      if (!reader.is_comment() && LooksLikeNumber(cells[0])) {
        reader.Fail(
            "expected a header line naming the columns (e.g. '#time(ns),px,py,pz,qw,qx,qy,qz'), "
            "found the data row '" +
            std::string(reader.line()) + "'");
      }
      std::string problem;
      layout = CsvLayoutFromHeader(cells, &problem);
      if (!layout) {
        reader.Fail("expected a header naming time, position and quaternion columns, found '" +
                    std::string(reader.line()) + "' (" + problem + ")");
      }
      continue;
    }
    if (reader.is_comment()) continue;
    ReadRow(reader, cells, *layout, &trajectory);
  }
  if (trajectory.empty()) throw EvalError(path + ": expected trajectory rows, found none");
  return trajectory;
}

void WriteEurocCsvTrajectory(const Trajectory& trajectory, const std::string& path) {
  std::ofstream out(path);
  if (!out) throw EvalError(path + ": cannot open for writing");
  bool velocity = !trajectory.empty();
  for (const PoseSample& s : trajectory) velocity = velocity && s.v_world_body_m_s.has_value();
  out << "#timestamp [ns],p_RS_R_x [m],p_RS_R_y [m],p_RS_R_z [m],q_RS_w [],q_RS_x [],q_RS_y [],"
         "q_RS_z []";
  if (velocity) out << ",v_RS_R_x [m s^-1],v_RS_R_y [m s^-1],v_RS_R_z [m s^-1]";
  out << "\n";
  for (const PoseSample& s : trajectory) {
    out << s.stamp.nanoseconds();
    for (int i = 0; i < 3; ++i) {
      out << ',';
      WriteNumber(out, s.p_world_body[i]);
    }
    for (const double c :
         {s.q_world_body.w(), s.q_world_body.x(), s.q_world_body.y(), s.q_world_body.z()}) {
      out << ',';
      WriteNumber(out, c);
    }
    if (velocity) {
      for (int i = 0; i < 3; ++i) {
        out << ',';
        WriteNumber(out, (*s.v_world_body_m_s)[i]);
      }
    }
    out << '\n';
  }
  out.flush();
  if (!out) throw EvalError(path + ": write failed");
}

}  // namespace rover::eval
