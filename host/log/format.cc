#include "host/log/format.h"

#include <cstdio>

#include "core/time/time.h"

namespace rover::host {

std::string FormatBytes(uint64_t bytes) {
  static constexpr const char* kUnits[] = {"B", "KiB", "MiB", "GiB", "TiB"};
  double value = static_cast<double>(bytes);
  std::size_t unit = 0;
  while (value >= 1024.0 && unit + 1 < std::size(kUnits)) {
    value /= 1024.0;
    ++unit;
  }
  char buf[32];
  if (unit == 0) {
    std::snprintf(buf, sizeof buf, "%llu B", static_cast<unsigned long long>(bytes));
  } else {
    std::snprintf(buf, sizeof buf, "%.2f %s", value, kUnits[unit]);
  }
  return buf;
}

std::string FormatLogTime(uint64_t log_time_ns) {
  return Time::FromNanoseconds(static_cast<int64_t>(log_time_ns)).ToString();
}

}  // namespace rover::host
