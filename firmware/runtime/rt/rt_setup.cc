#include "firmware/runtime/rt/rt_setup.h"

#include <alloca.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <thread>

namespace rover::runtime {
namespace {

constexpr int kCapSysNice = 23;  // linux/capability.h
constexpr std::size_t kStackMarginBytes = 64 * 1024;

uint64_t SoftLimit(int resource) {
  rlimit limit{};
  if (getrlimit(resource, &limit) != 0) return 0;
  return limit.rlim_cur == RLIM_INFINITY ? std::numeric_limits<uint64_t>::max()
                                         : static_cast<uint64_t>(limit.rlim_cur);
}

std::string LimitText(uint64_t value, uint64_t unit, const char* unit_name) {
  if (value == std::numeric_limits<uint64_t>::max()) return "unlimited";
  return std::to_string(value / unit) + unit_name;
}

// Bytes of the calling thread's stack between its lowest address and the
// current frame, or 0 if unknown.
std::size_t StackBytesBelowHere() {
  pthread_attr_t attr;
  if (pthread_getattr_np(pthread_self(), &attr) != 0) return 0;
  void* low = nullptr;
  std::size_t size = 0;
  const int rc = pthread_attr_getstack(&attr, &low, &size);
  pthread_attr_destroy(&attr);
  if (rc != 0 || low == nullptr) return 0;
  const auto here = reinterpret_cast<std::uintptr_t>(__builtin_frame_address(0));
  const auto bottom = reinterpret_cast<std::uintptr_t>(low);
  return here > bottom ? here - bottom : 0;
}

// Writes one byte per page of a `bytes`-long alloca block. noinline so that
// the block is released when it returns.
[[gnu::noinline]] void TouchStack(std::size_t bytes) {
  auto* block = static_cast<volatile unsigned char*>(alloca(bytes));
  const auto page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
  for (std::size_t i = 0; i < bytes; i += page) block[i] = 0;
  if (bytes > 0) block[bytes - 1] = 0;
}

}  // namespace

std::size_t RtSetup::PrefaultStack(std::size_t bytes) {
  const std::size_t available = StackBytesBelowHere();
  const std::size_t usable = available > kStackMarginBytes ? available - kStackMarginBytes : 0;
  const std::size_t n = bytes < usable ? bytes : usable;
  if (n > 0) TouchStack(n);
  return n;
}

int RtSetup::ProbeFifo(int priority, SetSchedParamFn set_sched_param) {
  int result = 0;
  // A throwaway thread: if SCHED_FIFO is granted, only it runs with it, and
  // it ends at once.
  std::thread probe([&result, priority, set_sched_param] {
    sched_param param{};
    param.sched_priority = priority;
    result = set_sched_param(pthread_self(), SCHED_FIFO, &param);
  });
  probe.join();
  return result;
}

bool RtSetup::HasCapSysNice() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("CapEff:", 0) != 0) continue;
    const uint64_t caps = std::strtoull(line.c_str() + 7, nullptr, 16);
    return ((caps >> kCapSysNice) & 1u) != 0;
  }
  return false;
}

std::string RtSetup::ErrnoName(int error) {
  const char* name = strerrorname_np(error);
  return name != nullptr ? std::string(name) : "errno " + std::to_string(error);
}

RtSetupReport RtSetup::Apply(const RtSetupOptions& options) {
  RtSetupReport r;
  r.rtprio_limit = SoftLimit(RLIMIT_RTPRIO);
  r.memlock_limit_bytes = SoftLimit(RLIMIT_MEMLOCK);
  r.has_cap_sys_nice = HasCapSysNice();

  r.lock_requested = options.lock_memory;
  if (options.lock_memory) {
    if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
      r.memory_locked = true;
    } else {
      r.lock_errno = errno;
    }
  }
  r.stack_prefaulted_bytes = PrefaultStack(options.stack_prefault_bytes);

  r.sched_errno = ProbeFifo(options.probe_priority, options.set_sched_param);
  r.rt_scheduling_allowed = r.sched_errno == 0;

  std::string why;
  if (!r.rt_scheduling_allowed) {
    why = "SCHED_FIFO refused: " + ErrnoName(r.sched_errno) + ", RLIMIT_RTPRIO " +
          LimitText(r.rtprio_limit, 1, "") +
          (r.has_cap_sys_nice ? ", CAP_SYS_NICE held" : ", no CAP_SYS_NICE");
  }
  const bool lock_failed = r.lock_requested && !r.memory_locked;
  if (lock_failed) {
    if (!why.empty()) why += "; ";
    why += "mlockall refused: " + ErrnoName(r.lock_errno) + ", RLIMIT_MEMLOCK " +
           LimitText(r.memlock_limit_bytes, 1024, " KiB");
  }
  if (!why.empty()) {
    std::string effect;
    if (!r.rt_scheduling_allowed) effect = "normal scheduling";
    if (lock_failed) effect += effect.empty() ? "pageable memory" : " and pageable memory";
    r.warning =
        options.program_name +
        (r.rt_scheduling_allowed ? ": memory not locked (" : ": no real-time privileges (") + why +
        "); running degraded with " + effect;
  }
  return r;
}

}  // namespace rover::runtime
