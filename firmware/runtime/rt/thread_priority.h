#ifndef ROVER_FIRMWARE_RUNTIME_RT_THREAD_PRIORITY_H_
#define ROVER_FIRMWARE_RUNTIME_RT_THREAD_PRIORITY_H_

// Lowers the CPU and I/O priority of a background thread (the log service,
// mapd's graph and loop-closure threads) so that it never competes with the
// threads that must keep up for the processor or the disk.

#include <string>

namespace rover::runtime {

/// An I/O scheduling class (ioprio_set(2)).
enum class IoPriorityClass {
  kUnchanged,   ///< Leave the thread's I/O priority alone.
  kBestEffort,  ///< IOPRIO_CLASS_BE with a level 0..7 (7 lowest).
  kIdle,        ///< IOPRIO_CLASS_IDLE: disk time only when nobody else wants it.
};

/// Sets the calling thread's nice value (setpriority(PRIO_PROCESS, tid)) and
/// I/O priority (ioprio_set(IOPRIO_WHO_PROCESS, tid) with `io_class`, and
/// `io_level` 0..7 for best effort). Only this thread changes. Returns an
/// empty string on success, else what failed and why (e.g. lowering the nice
/// value below the current one needs CAP_SYS_NICE); the caller decides
/// whether that is fatal.
std::string LowerCurrentThreadPriority(int nice, IoPriorityClass io_class, int io_level);

}  // namespace rover::runtime

#endif  // ROVER_FIRMWARE_RUNTIME_RT_THREAD_PRIORITY_H_
