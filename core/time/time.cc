#include "core/time/time.h"

#include <cmath>
#include <cstdio>
#include <ctime>

namespace rover {

Duration Duration::FromSeconds(double seconds) {
  return Duration(static_cast<int64_t>(std::llround(seconds * 1e9)));
}

std::string Duration::ToString() const {
  char buf[48];
  const int64_t mag = ns_ < 0 ? -ns_ : ns_;
  if (mag >= 1'000'000'000) {
    std::snprintf(buf, sizeof buf, "%.3f s", ToSeconds());
  } else if (mag >= 1'000'000) {
    std::snprintf(buf, sizeof buf, "%.3f ms", ToMilliseconds());
  } else if (mag >= 1'000) {
    std::snprintf(buf, sizeof buf, "%.3f us", ToMicroseconds());
  } else {
    std::snprintf(buf, sizeof buf, "%lld ns", static_cast<long long>(ns_));
  }
  return buf;
}

Time Time::FromSeconds(double seconds) {
  return Time(static_cast<int64_t>(std::llround(seconds * 1e9)));
}

Time Time::Now() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return Time(static_cast<int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec);
}

std::string Time::ToString() const {
  char buf[48];
  // Split the magnitude so that -0.5 s prints as "-0.500000000 s".
  const unsigned long long mag =
      ns_ < 0 ? 0ULL - static_cast<unsigned long long>(ns_) : static_cast<unsigned long long>(ns_);
  std::snprintf(buf, sizeof buf, "%s%llu.%09llu s", ns_ < 0 ? "-" : "", mag / 1'000'000'000ULL,
                mag % 1'000'000'000ULL);
  return buf;
}

}  // namespace rover
