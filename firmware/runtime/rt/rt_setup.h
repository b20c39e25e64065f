#ifndef ROVER_FIRMWARE_RUNTIME_RT_RT_SETUP_H_
#define ROVER_FIRMWARE_RUNTIME_RT_RT_SETUP_H_

// Process-wide real-time set-up, done once at start-up before the real-time
// threads start:
//   - mlockall(MCL_CURRENT | MCL_FUTURE), so no page of the process is ever
//     paged out or faulted in lazily by the kernel behind a real-time loop;
//   - a prefault of the calling thread's stack (touch N KiB below the
//     current frame), so its first deep call does not page-fault;
//   - a probe of whether SCHED_FIFO is permitted (on a throwaway thread, so
//     the caller's own scheduling is left alone).
//
// Without privileges nothing here fails: the report says what worked and
// carries ONE warning line for the caller to print once, e.g.
//   roverd: no real-time privileges (SCHED_FIFO refused: EPERM, RLIMIT_RTPRIO
//   0, no CAP_SYS_NICE); running degraded with normal scheduling
// (one line in the real output).
//
// Note: with MCL_FUTURE every later mapping is locked as it is made; under a
// small RLIMIT_MEMLOCK (unprivileged users) such mappings can then fail, which
// is why mlockall is only worth it together with preallocated pools.

#include <pthread.h>
#include <sched.h>

#include <cstddef>
#include <cstdint>
#include <string>

namespace rover::runtime {

/// Signature of pthread_setschedparam; tests inject a failing one.
using SetSchedParamFn = int (*)(pthread_t thread, int policy, const sched_param* param);

/// What RtSetup::Apply() should do.
struct RtSetupOptions {
  /// Prefix of the warning line ("roverd: ...").
  std::string program_name = "roverd";
  /// Call mlockall(MCL_CURRENT | MCL_FUTURE).
  bool lock_memory = true;
  /// Bytes of the calling thread's stack to touch (clamped to what the stack
  /// has left, minus a safety margin).
  std::size_t stack_prefault_bytes = 256 * 1024;
  /// SCHED_FIFO priority used by the privilege probe (1..99).
  int probe_priority = 1;
  /// Used by the probe to request SCHED_FIFO; pthread_setschedparam unless a
  /// test injects a failure.
  SetSchedParamFn set_sched_param = &pthread_setschedparam;
};

/// What RtSetup::Apply() achieved.
struct RtSetupReport {
  bool lock_requested = false;
  bool memory_locked = false;
  int lock_errno = 0;  ///< errno of mlockall when it failed.
  std::size_t stack_prefaulted_bytes = 0;
  bool rt_scheduling_allowed = false;
  int sched_errno = 0;  ///< Error of the SCHED_FIFO probe when refused.
  /// Soft RLIMIT_RTPRIO; UINT64_MAX for unlimited.
  uint64_t rtprio_limit = 0;
  /// Soft RLIMIT_MEMLOCK in bytes; UINT64_MAX for unlimited.
  uint64_t memlock_limit_bytes = 0;
  bool has_cap_sys_nice = false;
  /// Empty when everything requested worked; otherwise one line (no newline)
  /// saying what was refused and how the process degrades.
  std::string warning;

  /// True if real-time scheduling was refused or requested locking failed.
  bool degraded() const { return !rt_scheduling_allowed || (lock_requested && !memory_locked); }
};

/// Process-wide real-time set-up; see the file comment.
class RtSetup {
 public:
  RtSetup() = delete;

  /// Locks memory, prefaults the calling thread's stack and probes SCHED_FIFO
  /// as `options` asks. Never throws for missing privileges; see
  /// RtSetupReport::warning.
  static RtSetupReport Apply(const RtSetupOptions& options = {});

  /// Touches `bytes` of the calling thread's stack below the current frame,
  /// one write per page, clamped so that at least 64 KiB of the stack stay
  /// untouched below. Returns the number of bytes touched.
  static std::size_t PrefaultStack(std::size_t bytes);

  /// Asks for SCHED_FIFO at `priority` on a throwaway thread through
  /// `set_sched_param`. Returns 0 if granted, else the error number.
  static int ProbeFifo(int priority, SetSchedParamFn set_sched_param = &pthread_setschedparam);

  /// True if the effective capability set holds CAP_SYS_NICE (read from
  /// /proc/self/status; false if that cannot be read).
  static bool HasCapSysNice();

  /// Symbolic name of an error number ("EPERM"), or "errno N" if unknown.
  static std::string ErrnoName(int error);
};

}  // namespace rover::runtime

#endif  // ROVER_FIRMWARE_RUNTIME_RT_RT_SETUP_H_
