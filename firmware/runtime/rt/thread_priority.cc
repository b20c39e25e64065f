#include "firmware/runtime/rt/thread_priority.h"

#include <linux/ioprio.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <system_error>

namespace rover::runtime {
namespace {

std::string ErrnoText(int err) { return std::error_code(err, std::generic_category()).message(); }

}  // namespace

std::string LowerCurrentThreadPriority(int nice, IoPriorityClass io_class, int io_level) {
  std::string problems;
  const auto tid = static_cast<id_t>(::gettid());
  if (::setpriority(PRIO_PROCESS, tid, nice) != 0) {
    problems = "setpriority(nice " + std::to_string(nice) + ") failed: " + ErrnoText(errno);
  }
  if (io_class != IoPriorityClass::kUnchanged) {
    const int klass = io_class == IoPriorityClass::kIdle ? IOPRIO_CLASS_IDLE : IOPRIO_CLASS_BE;
    const int data = io_class == IoPriorityClass::kIdle ? 0 : io_level;
    const int value = (klass << IOPRIO_CLASS_SHIFT) | data;
    if (::syscall(SYS_ioprio_set, IOPRIO_WHO_PROCESS, static_cast<int>(tid), value) != 0) {
      if (!problems.empty()) problems += "; ";
      problems += std::string("ioprio_set(") +
                  (io_class == IoPriorityClass::kIdle ? "idle"
                                                      : "best effort " + std::to_string(io_level)) +
                  ") failed: " + ErrnoText(errno);
    }
  }
  return problems;
}

}  // namespace rover::runtime
