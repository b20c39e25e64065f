#ifndef ROVER_FIRMWARE_RUNTIME_LOG_SERVICE_THREAD_PRIORITY_H_
#define ROVER_FIRMWARE_RUNTIME_LOG_SERVICE_THREAD_PRIORITY_H_

// Lowers the CPU and I/O priority of a service thread so it never competes
// with the real-time threads for the processor or the disk.

#include <string>

#include "firmware/runtime/log_service/log_service_options.h"

namespace rover::runtime {

/// Sets the calling thread's nice value (setpriority(PRIO_PROCESS, tid)) and
/// I/O priority (ioprio_set(IOPRIO_WHO_PROCESS, tid) with `io_class`, and
/// `io_level` 0..7 for best effort). Only this thread changes. Returns an
/// empty string on success, else what failed and why (e.g. lowering the nice
/// value below the current one needs CAP_SYS_NICE); the caller decides
/// whether that is fatal.
std::string LowerCurrentThreadPriority(int nice, IoPriorityClass io_class, int io_level);

}  // namespace rover::runtime

#endif  // ROVER_FIRMWARE_RUNTIME_LOG_SERVICE_THREAD_PRIORITY_H_
