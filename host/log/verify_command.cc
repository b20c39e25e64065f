#include <cstdio>

#include "core/log/mcap/mcap_reader.h"
#include "host/log/commands.h"

namespace rover::host {

int RunVerify(const std::string& path, std::ostream& out, std::ostream& /*err*/) {
  const log::VerifyReport report = log::Verify(path);
  out << path << ": " << (report.ok ? "OK" : "DAMAGED") << "\n";
  out << "  messages readable: " << report.message_count << "\n";
  out << "  chunks:            " << report.chunk_count << " (" << report.damaged_chunk_count
      << " damaged)\n";
  out << "  schemas/channels:  " << report.schema_count << "/" << report.channel_count << "\n";
  out << "  summary:           "
      << (report.summary_ok ? "intact, consistent" : "missing or invalid") << "\n";
  out << "  truncated:         " << (report.truncated ? "yes" : "no") << "\n";
  for (const log::Damage& d : report.damage) {
    char offset[32];
    std::snprintf(offset, sizeof offset, "%12llu", static_cast<unsigned long long>(d.offset));
    out << "  damage at offset " << offset << ": " << d.what << "\n";
  }
  if (!report.ok) {
    out << "  the readable part can be saved with: rover-log recover " << path << " OUT.mcap\n";
  }
  return report.ok ? 0 : 1;
}

}  // namespace rover::host
