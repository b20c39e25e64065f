#ifndef ROVER_FIRMWARE_RUNTIME_LOG_SERVICE_LOG_SERVICE_H_
#define ROVER_FIRMWARE_RUNTIME_LOG_SERVICE_LOG_SERVICE_H_

// The board's HTTP log service (cpp-httplib): lists the flight logs of one
// folder and serves them for download, read-only, behind a bearer token.
//
//   GET /logs         JSON listing (core/log/archive/log_listing.h): name,
//                     size_bytes, start/end log time, sha256, complete.
//   GET /logs/NAME    the log's servable bytes, streamed from the file (never
//                     loaded into memory) and paced by the bandwidth limit.
//                     Range "bytes=a-b", "bytes=a-", "bytes=-n" gives 206 with
//                     Content-Range; an unsatisfiable range gives 416 with
//                     "Content-Range: bytes */size". Accept-Ranges: bytes;
//                     ETag: the quoted SHA-256 of the servable bytes.
//   HEAD              the same headers without a body.
//
// A log still being written (no valid footer and summary yet) is served only
// up to the end of its last complete MCAP record, so a downloader never gets
// a torn chunk; its listed size and sha256 refer to that length, which only
// grows, so a client that asks for exactly the listed range gets exactly the
// listed bytes even while the log grows (core/log/archive/mcap_servable.h).
//
// Every request needs "Authorization: Bearer <token>" (compared in constant
// time); the answers are:
//   401 missing or wrong token (WWW-Authenticate: Bearer),
//   405 any method but GET and HEAD (Allow: GET, HEAD). cpp-httplib answers
//       two kinds of request itself, before routing: a malformed Range header
//       (416 with a body saying what was expected, after the token check
//       here too) and a request line it cannot parse or an overlong URI, e.g.
//       a method it does not know (400 or 414 without a body, before any
//       header is read; nothing is served),
//   400 a name that is not a plain MCAP file name (log::IsValidLogName): any
//       '/', "..", NUL, '%' or leading '.' is refused before the file system
//       is touched; URL escapes are decoded first, so "%2e%2e%2f" is "../",
//   403 a symbolic link in the folder that resolves outside it,
//   404 no such log (or not a regular file), or a path other than /logs[/NAME],
//   503 all `max_concurrent_transfers` transfers busy (Retry-After: seconds).
//       A transfer holds its slot until its last chunk is handed to the
//       socket, so a client that has received every byte finds it free.
// Every error body is one line of text saying what was expected and found.
//
// Threads: Start() binds and starts a listener thread, which runs a pool of
// max_concurrent_transfers + 2 workers (so listings and refusals are answered
// while every transfer slot is busy). Each of these threads lowers its own
// CPU and I/O priority (nice, ioprio idle/best effort); a failure to do so is
// reported once on stderr and by priority_warning(), and is not fatal.
//
// Costs: a log's SHA-256 is computed once and then extended with the bytes
// it grows by (cached per file), but the first listing after start-up hashes
// every log in full at the service's idle I/O priority; clients should allow
// for that with their read timeout. Stop() waits for running transfers to
// reach their next chunk, at most the write timeout for a stalled client.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "firmware/runtime/log_service/log_service_options.h"

namespace rover::runtime {

/// What the service has done since it was constructed (over Start/Stop cycles).
struct LogServiceCounters {
  uint64_t requests = 0;                ///< Every request that reached the service.
  uint64_t listings = 0;                ///< GET/HEAD /logs answered.
  uint64_t transfers_started = 0;       ///< GET /logs/NAME admitted with a body to send.
  uint64_t transfers_completed = 0;     ///< ... whose every byte was handed to the socket.
  uint64_t transfers_aborted = 0;       ///< ... ended early (client gone, hook, Stop()).
  uint64_t active_transfers = 0;        ///< Transfers holding a slot right now.
  uint64_t partial_responses = 0;       ///< 206 answers to Range requests.
  uint64_t bytes_served = 0;            ///< Log bytes written to sockets.
  uint64_t refused_unauthorized = 0;    ///< 401
  uint64_t refused_method = 0;          ///< 405
  uint64_t refused_bad_name = 0;        ///< 400
  uint64_t refused_not_found = 0;       ///< 404
  uint64_t refused_outside_folder = 0;  ///< 403
  uint64_t refused_busy = 0;            ///< 503
  uint64_t refused_range = 0;           ///< 416
  uint64_t internal_errors = 0;         ///< 500 (unreadable file, unexpected exception)
};

/// Test hooks; empty in production.
struct LogServiceHooks {
  /// Called by a transfer before it sends the bytes of log `name` that start
  /// at file offset `offset_bytes`. Returning false closes the connection
  /// there, as a cut link would. It may block (tests hold transfers open
  /// with it), but must return for Stop() to finish.
  std::function<bool(const std::string& name, uint64_t offset_bytes)> before_send;
};

class LogService {
 public:
  explicit LogService(LogServiceOptions options, LogServiceHooks hooks = {});
  /// Stop()s the service.
  ~LogService();
  LogService(const LogService&) = delete;
  LogService& operator=(const LogService&) = delete;

  /// Validates the options, loads the token, checks the log folder, binds
  /// bind_address:port and starts serving; returns once the service accepts
  /// requests. Throws std::invalid_argument for bad options, and
  /// std::runtime_error if the token cannot be loaded, the folder is not a
  /// directory, the address cannot be bound, or the service is running.
  void Start();

  /// Stops accepting, ends running transfers at their next chunk, and joins
  /// every service thread. Idempotent; Start() may be called again after it.
  void Stop();

  /// True between Start() and Stop().
  bool running() const;

  /// The bound TCP port (the kernel's pick when options.port is 0); 0 before
  /// Start().
  int port() const;

  /// A snapshot of the counters; callable from any thread.
  LogServiceCounters counters() const;

  /// Why the service threads could not lower their priority, or empty.
  std::string priority_warning() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rover::runtime

#endif  // ROVER_FIRMWARE_RUNTIME_LOG_SERVICE_LOG_SERVICE_H_
