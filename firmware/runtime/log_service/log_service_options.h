#ifndef ROVER_FIRMWARE_RUNTIME_LOG_SERVICE_LOG_SERVICE_OPTIONS_H_
#define ROVER_FIRMWARE_RUNTIME_LOG_SERVICE_LOG_SERVICE_OPTIONS_H_

// Options of the board's HTTP log service (the `log_service` section of a
// board config):
//
//   log_service:
//     bind_address: 127.0.0.1        # an address of this board, never a host name
//     port: 8086                     # 0: any free port (LogService::port() says which)
//     log_folder: /var/lib/rover/logs
//     token_file: /etc/rover/log_service.token   # or `token: ...` (not both)
//     max_concurrent_transfers: 2
//     bandwidth_limit_bytes_per_s: 20000000      # all transfers together; 0: unlimited
//     nice: 10                       # setpriority() of the service threads, -20..19
//     io_class: idle                 # ioprio_set(): idle | best_effort | unchanged
//     io_level: 7                    # best_effort level 0 (high) .. 7 (low)
//     retry_after_s: 5               # Retry-After of a 503 when all transfers are busy
//
// Every key is optional except the log folder and one of token / token_file.

#include <cstdint>
#include <string>

#include "core/config/config.h"
#include "firmware/runtime/rt/thread_priority.h"

namespace rover::runtime {

struct LogServiceOptions {
  std::string bind_address = "127.0.0.1";
  int port = 0;  ///< 0: let the kernel pick a free port.
  std::string log_folder;
  /// The bearer token clients must present. Either this or token_file.
  std::string token;
  /// File holding the token (surrounding whitespace and the final newline are
  /// stripped). Read by LoadToken() when the service starts.
  std::string token_file;
  int max_concurrent_transfers = 2;
  /// Shared by all transfers; 0 means unlimited.
  uint64_t bandwidth_limit_bytes_per_s = 20'000'000;
  int nice = 10;
  IoPriorityClass io_class = IoPriorityClass::kIdle;
  int io_level = 7;
  int retry_after_s = 5;
  /// Socket read / write timeouts of a connection.
  int read_timeout_s = 5;
  int write_timeout_s = 10;

  /// Reads the keys listed at the top of this file from `node` (absent keys
  /// keep their defaults), then Validate(). Throws ConfigError for a bad
  /// value, located at its key.
  static LogServiceOptions Load(const ConfigNode& node);

  /// Throws std::invalid_argument naming the first bad value with what was
  /// expected and what was found: empty bind_address or log_folder, port
  /// outside 0..65535, neither or both of token and token_file, fewer than 1
  /// or more than 64 concurrent transfers, nice outside -20..19, io_level
  /// outside 0..7, retry_after_s outside 1..3600, timeouts outside 1..600 s.
  void Validate() const;

  /// The token: `token`, or the contents of `token_file` without surrounding
  /// whitespace. Throws std::runtime_error if the file cannot be read or the
  /// token is empty or contains whitespace or control characters.
  std::string LoadToken() const;
};

}  // namespace rover::runtime

#endif  // ROVER_FIRMWARE_RUNTIME_LOG_SERVICE_LOG_SERVICE_OPTIONS_H_
