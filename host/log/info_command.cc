#include <cstdio>
#include <map>
#include <set>

#include "core/log/mcap/mcap_reader.h"
#include "host/log/commands.h"
#include "host/log/format.h"

namespace rover::host {
namespace {

struct ChannelSummary {
  uint64_t count = 0;
  uint64_t first_ns = 0;
  uint64_t last_ns = 0;
};

std::string CompressionLine(const std::vector<log::ChunkInfo>& chunks) {
  if (chunks.empty()) return "no chunks";
  std::map<std::string, uint64_t> by_codec;
  uint64_t compressed = 0, uncompressed = 0;
  for (const log::ChunkInfo& c : chunks) {
    ++by_codec[c.compression.empty() ? "none" : c.compression];
    compressed += c.compressed_size;
    uncompressed += c.uncompressed_size;
  }
  std::string line;
  for (const auto& [codec, n] : by_codec) {
    line += (line.empty() ? "" : ", ") + codec + " (" + std::to_string(n) + " chunks)";
  }
  char ratio[64];
  std::snprintf(
      ratio, sizeof ratio, "; %s -> %s, ratio %.2f", FormatBytes(uncompressed).c_str(),
      FormatBytes(compressed).c_str(),
      compressed > 0 ? static_cast<double>(uncompressed) / static_cast<double>(compressed) : 0.0);
  return line + ratio;
}

}  // namespace

int RunInfo(const std::string& path, std::ostream& out, std::ostream& err) {
  std::optional<log::McapReader> opened;
  try {
    opened.emplace(log::McapReader::Open(path));
  } catch (const std::exception& e) {
    err << "rover-log info: " << e.what() << "\n";
    return 2;
  }
  log::McapReader& reader = *opened;

  std::map<uint16_t, ChannelSummary> per_channel;
  reader.ForEachMessage([&](const log::MessageView& m) {
    ChannelSummary& s = per_channel[m.channel_id];
    if (s.count == 0 || m.log_time < s.first_ns) s.first_ns = m.log_time;
    if (s.count == 0 || m.log_time > s.last_ns) s.last_ns = m.log_time;
    ++s.count;
    return true;
  });

  uint64_t total = 0, start = UINT64_MAX, end = 0;
  for (const auto& [id, s] : per_channel) {
    total += s.count;
    start = std::min(start, s.first_ns);
    end = std::max(end, s.last_ns);
  }

  out << "file:         " << path << " (" << FormatBytes(reader.file_size()) << ")\n";
  out << "profile:      " << reader.header().profile << "  (written by " << reader.header().library
      << ")\n";
  out << "summary:      "
      << (reader.summary_ok()
              ? "intact"
              : (reader.truncated() ? "missing: file truncated, data section scanned"
                                    : "unusable, data section scanned"))
      << "\n";
  out << "compression:  " << CompressionLine(reader.chunks()) << "\n";
  if (total > 0) {
    char duration[32];
    std::snprintf(duration, sizeof duration, "%.3f s", static_cast<double>(end - start) * 1e-9);
    out << "time range:   " << FormatLogTime(start) << " .. " << FormatLogTime(end) << "  ("
        << duration << ")\n";
  } else {
    out << "time range:   (no messages)\n";
  }
  out << "messages:     " << total << " in " << reader.channels().size() << " channels\n";
  if (!reader.metadata().empty()) {
    std::set<std::string> names;
    for (const auto& m : reader.metadata()) names.insert(m.name);
    out << "metadata:     ";
    for (const auto& n : names) out << n << (n == *names.rbegin() ? "\n" : ", ");
  }
  out << "channels:\n";
  char line[512];
  std::snprintf(line, sizeof line, "  %4s  %-28s %-36s %9s %9s  %s\n", "id", "topic", "schema",
                "messages", "rate_hz", "first .. last");
  out << line;
  for (const auto& [id, channel] : reader.channels()) {
    const ChannelSummary s = per_channel.count(id) ? per_channel.at(id) : ChannelSummary{};
    const auto schema = reader.schemas().find(channel.schema_id);
    const std::string schema_name = schema == reader.schemas().end() ? "-" : schema->second.name;
    const double span_s = static_cast<double>(s.last_ns - s.first_ns) * 1e-9;
    const double rate = s.count > 1 && span_s > 0 ? static_cast<double>(s.count - 1) / span_s : 0;
    std::snprintf(line, sizeof line, "  %4u  %-28s %-36s %9llu %9.2f  %s .. %s\n",
                  static_cast<unsigned>(id), channel.topic.c_str(), schema_name.c_str(),
                  static_cast<unsigned long long>(s.count), rate,
                  s.count ? FormatLogTime(s.first_ns).c_str() : "-",
                  s.count ? FormatLogTime(s.last_ns).c_str() : "-");
    out << line;
  }
  if (!reader.damage().empty()) {
    out << "damage:       " << reader.damage().size()
        << " problem(s); run `rover-log verify` for details\n";
    return 1;
  }
  return 0;
}

}  // namespace rover::host
