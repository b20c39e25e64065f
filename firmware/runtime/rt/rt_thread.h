#ifndef ROVER_FIRMWARE_RUNTIME_RT_RT_THREAD_H_
#define ROVER_FIRMWARE_RUNTIME_RT_RT_THREAD_H_

// A named thread with real-time scheduling, CPU affinity and a prefaulted
// stack.
//
// The new thread configures itself before running its body: name, CPU
// affinity, SCHED_FIFO at the requested priority (or SCHED_OTHER with a nice
// value for priority 0), stack prefault. The constructor returns once that
// is done, so report() then says what the thread actually obtained (read
// back from the kernel). A refused SCHED_FIFO (no privileges) or a refused
// affinity never fails the thread: it runs degraded with SCHED_OTHER and the
// report says why (report().Describe()).

#include <pthread.h>

#include <cstddef>
#include <functional>
#include <stop_token>
#include <string>
#include <thread>
#include <vector>

#include "firmware/runtime/rt/rt_setup.h"
#include "firmware/runtime/rt/rt_thread_options.h"

namespace rover::runtime {

/// Scheduling policy a thread ended up with.
enum class SchedPolicy { kOther, kFifo, kRoundRobin, kUnknown };

/// Name of a policy as the kernel spells it ("SCHED_FIFO").
const char* SchedPolicyName(SchedPolicy policy);

/// What an RtThread obtained, read back from the kernel after set-up.
struct RtThreadReport {
  std::string name;
  int requested_priority = 0;
  SchedPolicy policy = SchedPolicy::kUnknown;
  int priority = 0;     ///< Real-time priority obtained (0 under SCHED_OTHER).
  int nice = 0;         ///< Nice value obtained.
  int sched_errno = 0;  ///< Why SCHED_FIFO was refused (0 if granted or not asked).
  int nice_errno = 0;   ///< Why the nice value was refused (0 if applied).
  bool name_set = false;
  std::vector<int> cpus;  ///< Requested affinity; empty = any CPU.
  bool affinity_set = false;
  int affinity_errno = 0;  ///< Why the affinity was refused (0 if applied).
  std::size_t stack_prefaulted_bytes = 0;

  /// True if the thread asked for SCHED_FIFO and did not get it, or its
  /// affinity or nice value was refused.
  bool degraded() const;

  /// One line, e.g. "imu: SCHED_FIFO 80, cpus 1, 64 KiB stack prefaulted" or
  /// "imu: SCHED_OTHER nice 0 (SCHED_FIFO 80 refused: EPERM), any CPU, ...".
  std::string Describe() const;
};

/// A std::jthread started with RtThreadOptions; joins on destruction.
class RtThread {
 public:
  /// The thread's work; it should return soon after `stop` is requested.
  using Body = std::function<void(std::stop_token stop)>;

  /// Validates `options` (throws std::invalid_argument naming the field),
  /// starts the thread, waits until it has applied its settings and then
  /// lets it run `body`. `set_sched_param` requests the policy; tests inject
  /// a failing one to simulate missing privileges.
  RtThread(const RtThreadOptions& options, Body body,
           SetSchedParamFn set_sched_param = &pthread_setschedparam);
  RtThread(const RtThread&) = delete;
  RtThread& operator=(const RtThread&) = delete;

  /// Requests stop and joins.
  ~RtThread();

  /// What the thread obtained; complete when the constructor has returned.
  const RtThreadReport& report() const { return report_; }

  /// Asks the body to stop (through its stop token).
  void RequestStop() { thread_.request_stop(); }

  /// Waits for the body to return. Safe to call more than once.
  void Join();

 private:
  // Runs on the new thread before the body; fills report_.
  void Configure(const RtThreadOptions& options, SetSchedParamFn set_sched_param);

  RtThreadReport report_;
  std::jthread thread_;
};

}  // namespace rover::runtime

#endif  // ROVER_FIRMWARE_RUNTIME_RT_RT_THREAD_H_
