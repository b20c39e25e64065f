#ifndef ROVER_CORE_LOG_MSGS_BUILTIN_INTERFACES_H_
#define ROVER_CORE_LOG_MSGS_BUILTIN_INTERFACES_H_

// builtin_interfaces/msg/Time and its conversion from rover::Time.

#include <cstdint>
#include <limits>
#include <string_view>

#include "core/log/cdr/cdr_reader.h"
#include "core/log/cdr/cdr_writer.h"
#include "core/log/msgs/message_traits.h"
#include "core/time/time.h"

namespace rover::log {
namespace builtin_interfaces {

/// builtin_interfaces/msg/Time: seconds plus nanoseconds in [0, 1e9).
struct Time {
  int32_t sec = 0;
  uint32_t nanosec = 0;

  friend bool operator==(const Time&, const Time&) = default;
};

void Serialize(const Time& msg, CdrWriter& writer);
bool Deserialize(CdrReader& reader, Time* msg);

}  // namespace builtin_interfaces

template <>
struct MessageTraits<builtin_interfaces::Time> {
  static constexpr std::string_view kName = "builtin_interfaces/msg/Time";
  static std::string_view Definition();
};

/// Splits a rover::Time (CLOCK_MONOTONIC nanoseconds) into ROS sec/nanosec.
/// Negative times floor, so nanosec stays in [0, 1e9): -1 ns is {-1, 999999999}.
/// Times beyond the int32 seconds range (~68 years) saturate to its bounds.
constexpr builtin_interfaces::Time ToRosTime(::rover::Time time) {
  constexpr int64_t kNanosPerSecond = 1'000'000'000;
  const int64_t ns = time.nanoseconds();
  int64_t sec = ns / kNanosPerSecond;
  int64_t nanosec = ns % kNanosPerSecond;
  if (nanosec < 0) {
    --sec;
    nanosec += kNanosPerSecond;
  }
  if (sec > std::numeric_limits<int32_t>::max()) {
    return {std::numeric_limits<int32_t>::max(), static_cast<uint32_t>(kNanosPerSecond - 1)};
  }
  if (sec < std::numeric_limits<int32_t>::min()) {
    return {std::numeric_limits<int32_t>::min(), 0};
  }
  return {static_cast<int32_t>(sec), static_cast<uint32_t>(nanosec)};
}

/// Inverse of ToRosTime: sec * 1e9 + nanosec. Exact for every ROS time
/// (including nanosec >= 1e9, which is simply carried into the seconds).
constexpr ::rover::Time FromRosTime(const builtin_interfaces::Time& time) {
  return ::rover::Time::FromNanoseconds(int64_t{time.sec} * 1'000'000'000 + int64_t{time.nanosec});
}

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_MSGS_BUILTIN_INTERFACES_H_
