#ifndef ROVER_HOST_LOG_COMMANDS_H_
#define ROVER_HOST_LOG_COMMANDS_H_

// The subcommands of `rover-log`, as functions writing to streams so tests
// can call them directly. Each returns the process exit status:
//   0 success, 1 the file is damaged (verify) or partly unreadable,
//   2 bad usage or unreadable input.

#include <cstddef>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

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

struct MapOptions {
  /// mapd's logs (mapd-<time>-<pid>.mcap), in the order mapd wrote them;
  /// a restarted mapd leaves several.
  std::vector<std::string> mapd_logs;
  /// roverd's flight log, whose frame switches place every submap in the
  /// mission's frame 0. Empty: one mapd log only, its submaps chained by
  /// their SubmapInfo origins from the first submap's frame.
  std::string roverd_log;
  /// Output path without extension: STEM.bt, STEM.ot, STEM.ply.
  std::string out_stem;
  bool write_bt = true;
  bool write_ot = true;
  bool write_ply = true;
  /// Compose the point cloud (needed for the .ply); --no-cloud clears it.
  bool compose_cloud = true;
  /// Place submaps at the pose graph's optimised origins when the mapd logs
  /// hold them (the last log's last update); false (--chain): by the frame
  /// switches only, as the filter saw them.
  bool use_graph = true;
  /// Progress lines on `err` once at least this many submaps are composed.
  std::size_t progress_min_submaps = 20;
};

/// `rover-log map MAPD_LOG... [--roverd-log ROVERD] --out STEM`: the global
/// map of a mission from the submaps mapd logged, each placed at its frame's
/// origin and merged (octree and point cloud), written as STEM.bt / .ot /
/// .ply. Prints per log its submaps and the problems found (reading goes on
/// past damage), the submaps that could not be placed, and the composed
/// map's size, memory and compose time. Exit 0 ok, 1 the map was written but
/// input was damaged or submaps were left out, 2 bad usage, an unreadable
/// or non-MCAP file, no submaps at all, or an output that cannot be written.
int RunMap(const MapOptions& options, std::ostream& out, std::ostream& err);

/// How `list` and `download` reach the board's log service.
struct LogServiceAccess {
  std::string url;         ///< "http://HOST:PORT".
  std::string token;       ///< --token (visible in `ps`; prefer a token file).
  std::string token_file;  ///< --token-file; else ROVER_LOG_TOKEN is used.
  int connect_timeout_s = 5;
  int read_timeout_s = 30;
};

struct ListOptions {
  LogServiceAccess access;
  bool json = false;  ///< Print the service's JSON listing as received.
};

/// `rover-log list --url URL --token-file FILE [--json]`: one row per log on
/// the board: name, size, duration and first log time, complete or
/// in-progress, SHA-256 prefix. Exit 0 ok, 1 network or service failure,
/// 2 bad URL, missing or refused token.
int RunList(const ListOptions& options, std::ostream& out, std::ostream& err);

/// Test hooks of RunDownload; empty in the tool.
struct DownloadHooks {
  /// After the listing was fetched, before any byte is requested.
  std::function<void()> after_listing;
  /// When NAME.part holds every listed byte, before its SHA-256 is checked.
  std::function<void(const std::string& part_path)> before_verify;
};

struct DownloadOptions {
  LogServiceAccess access;
  std::string name;           ///< Log name as listed (a plain file name).
  std::string out_dir = ".";  ///< Created if missing.
  /// Attempts in a row that may fail without receiving a byte before giving
  /// up; an attempt that makes progress resets the count.
  int retries = 5;
  double initial_backoff_s = 0.5;  ///< Wait before the first retry; doubles per retry.
  double max_backoff_s = 10.0;     ///< Longest wait between attempts (also caps Retry-After).
  /// Redraw one progress line in place (stderr is a terminal); otherwise a
  /// line at every 10 %.
  bool progress_tty = false;
  DownloadHooks hooks;
};

/// `rover-log download NAME --url URL --token-file FILE [--out DIR]`: fetches
/// the listed bytes of NAME into DIR/NAME.part (resuming from its size with a
/// Range request, also after a cut connection), shows progress with rate and
/// ETA on `err`, checks the SHA-256 against the listing and only then renames
/// the file to DIR/NAME (atomically, replacing an older DIR/NAME only then).
/// On a mismatch the .part file is deleted and nothing is left under NAME.
/// The listed size is what is fetched: a log still being written comes down
/// up to its last complete record at listing time. Exit 0 ok, 1 network
/// failure after the retries, hash mismatch or service error, 2 bad input
/// (name, URL, token, folder, a name the service does not list, a refused
/// token).
int RunDownload(const DownloadOptions& options, std::ostream& out, std::ostream& err);

}  // namespace rover::host

#endif  // ROVER_HOST_LOG_COMMANDS_H_
