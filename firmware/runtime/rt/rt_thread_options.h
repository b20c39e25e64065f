#ifndef ROVER_FIRMWARE_RUNTIME_RT_RT_THREAD_OPTIONS_H_
#define ROVER_FIRMWARE_RUNTIME_RT_RT_THREAD_OPTIONS_H_

// Scheduling options of one firmware thread, from the board config:
//
//   threads:
//     imu:
//       name: imu                  # thread name (at most 15 characters)
//       priority: 80               # SCHED_FIFO 1..99; 0 = SCHED_OTHER
//       nice: 0                    # SCHED_OTHER nice (-20..19), also the fallback
//       cpus: [1]                  # CPU affinity; [] or absent = any CPU
//       stack_prefault_bytes: 262144

#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/config/config.h"

namespace rover::runtime {

/// How an RtThread is named, scheduled and placed.
struct RtThreadOptions {
  /// Longest name the kernel keeps (TASK_COMM_LEN - 1).
  static constexpr std::size_t kMaxNameLength = 15;
  /// Largest stack prefault accepted (the default thread stack is 8 MiB).
  static constexpr std::size_t kMaxStackPrefaultBytes = 4 * 1024 * 1024;

  std::string name;
  /// SCHED_FIFO priority 1..99; 0 asks for SCHED_OTHER with `nice`.
  int priority = 0;
  /// Nice value for SCHED_OTHER (priority 0, or when SCHED_FIFO is refused).
  int nice = 0;
  /// CPUs the thread may run on; empty means any.
  std::vector<int> cpus;
  /// Bytes of the new thread's stack to touch before its body runs.
  std::size_t stack_prefault_bytes = 64 * 1024;

  /// Reads the options from `node`; every key is optional, `name` defaults to
  /// `default_name`. Throws ConfigError naming the key for any invalid value
  /// (see Problem()).
  static RtThreadOptions Load(const ConfigNode& node, const std::string& default_name = "");

  /// The first invalid field as (key, "expected ..., found ...") or nullopt
  /// if the options are valid: name non-empty and at most 15 characters,
  /// priority in [0, 99], nice in [-20, 19], every CPU id in
  /// [0, hardware_concurrency) and listed once, stack prefault at most 4 MiB.
  std::optional<std::pair<std::string, std::string>> Problem() const;

  /// Throws std::invalid_argument "RtThreadOptions.<key>: <message>" if
  /// Problem() finds one.
  void Validate() const;
};

}  // namespace rover::runtime

#endif  // ROVER_FIRMWARE_RUNTIME_RT_RT_THREAD_OPTIONS_H_
