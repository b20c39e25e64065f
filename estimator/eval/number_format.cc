#include "estimator/eval/number_format.h"

#include <charconv>
#include <cstdint>
#include <cstdio>

namespace rover::eval {

std::string FormatDouble(double value) {
  char buffer[64];
  const auto [ptr, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
  if (ec != std::errc()) return "nan";
  return std::string(buffer, ptr);
}

std::string FormatSeconds(Time time) {
  const int64_t ns = time.nanoseconds();
  // Work on the magnitude as unsigned so INT64_MIN does not overflow.
  const uint64_t magnitude =
      ns < 0 ? static_cast<uint64_t>(-(ns + 1)) + 1u : static_cast<uint64_t>(ns);
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, "%s%llu.%09llu", ns < 0 ? "-" : "",
                static_cast<unsigned long long>(magnitude / 1'000'000'000u),
                static_cast<unsigned long long>(magnitude % 1'000'000'000u));
  return buffer;
}

}  // namespace rover::eval
