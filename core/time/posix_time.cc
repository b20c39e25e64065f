#include "core/time/posix_time.h"

#include <algorithm>
#include <cerrno>

namespace rover {
namespace {

constexpr int64_t kNsPerS = 1'000'000'000;

timespec FromNanoseconds(int64_t ns) {
  ns = std::max<int64_t>(0, ns);
  return timespec{static_cast<time_t>(ns / kNsPerS), static_cast<long>(ns % kNsPerS)};
}

}  // namespace

timespec ToTimespec(Duration d) { return FromNanoseconds(d.nanoseconds()); }

timespec ToTimespec(Time t) { return FromNanoseconds(t.nanoseconds()); }

void SleepUntil(Time t) {
  const timespec deadline = ToTimespec(t);
  // clock_nanosleep returns the error number; with TIMER_ABSTIME a retry
  // after a signal sleeps the rest of the way to the same deadline.
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &deadline, nullptr) == EINTR) {
  }
}

void SleepFor(Duration d) {
  if (d > Duration::Zero()) SleepUntil(Time::Now() + d);
}

}  // namespace rover
