#include "core/time/realtime_to_monotonic.h"

#include <time.h>

namespace rover {
namespace {

int64_t RealtimeNs() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}

}  // namespace

Time RealtimeToMonotonic::ToMonotonic(int64_t realtime_ns) {
  Refresh();
  return Time::FromNanoseconds(realtime_ns - real_minus_mono_ns_);
}

void RealtimeToMonotonic::Refresh() {
  const Time before = Time::Now();
  if (valid_ && before - read_at_ < refresh_period_) return;
  // The first offset must be had: after 20 wide brackets the last one is
  // taken. Later ones are only refreshments, tried once per period.
  const int attempts = valid_ ? 1 : 20;
  for (int attempt = 0; attempt < attempts; ++attempt) {
    const Time m1 = attempt == 0 ? before : Time::Now();
    const int64_t real = RealtimeNs();
    const Time m2 = Time::Now();
    const bool tight = m2 - m1 <= tight_bracket_;
    const bool last_chance = !valid_ && attempt == attempts - 1;
    if (tight || last_chance) {
      real_minus_mono_ns_ = real - (m1.nanoseconds() + (m2 - m1).nanoseconds() / 2);
      read_at_ = m2;
      valid_ = true;
      return;
    }
  }
}

}  // namespace rover
