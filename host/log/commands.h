#ifndef ROVER_HOST_LOG_COMMANDS_H_
#define ROVER_HOST_LOG_COMMANDS_H_

// The subcommands of `rover-log`, as functions writing to streams so tests
// can call them directly. Each returns the process exit status:
//   0 success, 1 the file is damaged (verify) or partly unreadable,
//   2 bad usage or unreadable input.

#include <ostream>
#include <string>

#include "core/log/mcap/mcap_writer.h"

namespace rover::host {

/// `rover-log info FILE`: header, compression, time range and one line per
/// channel (topic, schema, message count, rate, first/last log time).
int RunInfo(const std::string& path, std::ostream& out, std::ostream& err);

struct ExportOptions {
  std::string path;
  std::string topic;
  /// Where the CSV goes; "-" or empty is `out`.
  std::string output;
};

/// `rover-log export FILE --csv TOPIC`: one CSV row per message of TOPIC,
/// columns log_time_ns, sequence, then every leaf field of the message type
/// decoded from the schema in the file ("header.stamp.sec", ...).
int RunExport(const ExportOptions& options, std::ostream& out, std::ostream& err);

/// `rover-log verify FILE`: checks every CRC and index; lists damage with
/// file offsets. Exit 0 only for an intact file.
int RunVerify(const std::string& path, std::ostream& out, std::ostream& err);

/// `rover-log recover IN OUT`: rewrites the readable part of IN into a valid
/// file OUT and reports what could not be saved.
int RunRecover(const std::string& in, const std::string& out_path,
               const log::McapWriterOptions& options, std::ostream& out, std::ostream& err);

}  // namespace rover::host

#endif  // ROVER_HOST_LOG_COMMANDS_H_
