#include "core/log/mcap/mcap_reader.h"
#include "host/log/commands.h"

namespace rover::host {

int RunRecover(const std::string& in, const std::string& out_path,
               const log::McapWriterOptions& options, std::ostream& out, std::ostream& err) {
  if (in == out_path) {
    err << "rover-log recover: OUT must differ from IN (the damaged file is never modified)\n";
    return 2;
  }
  log::RecoverResult result;
  try {
    result = log::Recover(in, out_path, options);
  } catch (const std::exception& e) {
    err << "rover-log recover: " << e.what() << "\n";
    return 2;
  }
  out << "recovered " << result.messages_written << " messages from " << result.chunks_recovered
      << " intact chunks into " << out_path << "\n";
  if (result.input_truncated) out << "input was truncated (no footer)\n";
  if (result.chunks_dropped > 0 || result.messages_dropped > 0) {
    out << "lost: " << result.chunks_dropped << " damaged chunks, about " << result.messages_dropped
        << " messages\n";
  }
  for (const log::Damage& d : result.dropped) {
    out << "  offset " << d.offset << ": " << d.what << "\n";
  }
  return 0;
}

}  // namespace rover::host
