#ifndef ROVER_CORE_TIME_TIME_H_
#define ROVER_CORE_TIME_TIME_H_

// Strong time types over int64 nanoseconds.
//
// Every timestamp in the system is a point on CLOCK_MONOTONIC expressed in
// nanoseconds. `Time` is a point, `Duration` a signed span; mixing them up
// (adding two points, passing a span where a stamp is expected) does not
// compile. Both are trivially copyable and fit in a register, so they cost
// nothing in the real-time path.

#include <compare>
#include <cstdint>
#include <limits>
#include <string>

namespace rover {

/// A signed span of time in integer nanoseconds.
class Duration {
 public:
  constexpr Duration() = default;

  static constexpr Duration Nanoseconds(int64_t ns) { return Duration(ns); }
  static constexpr Duration Microseconds(int64_t us) { return Duration(us * 1'000); }
  static constexpr Duration Milliseconds(int64_t ms) { return Duration(ms * 1'000'000); }
  static constexpr Duration Seconds(int64_t s) { return Duration(s * 1'000'000'000); }
  /// Rounds to the nearest nanosecond (half away from zero).
  static Duration FromSeconds(double seconds);
  static constexpr Duration Zero() { return Duration(0); }
  static constexpr Duration Max() { return Duration(std::numeric_limits<int64_t>::max()); }

  constexpr int64_t nanoseconds() const { return ns_; }
  constexpr double ToSeconds() const { return static_cast<double>(ns_) * 1e-9; }
  constexpr double ToMilliseconds() const { return static_cast<double>(ns_) * 1e-6; }
  constexpr double ToMicroseconds() const { return static_cast<double>(ns_) * 1e-3; }

  constexpr Duration operator-() const { return Duration(-ns_); }
  constexpr Duration operator+(Duration o) const { return Duration(ns_ + o.ns_); }
  constexpr Duration operator-(Duration o) const { return Duration(ns_ - o.ns_); }
  constexpr Duration operator*(int64_t k) const { return Duration(ns_ * k); }
  constexpr Duration operator/(int64_t k) const { return Duration(ns_ / k); }
  /// Ratio of two spans, e.g. the interpolation fraction between samples.
  constexpr double operator/(Duration o) const {
    return static_cast<double>(ns_) / static_cast<double>(o.ns_);
  }
  constexpr Duration& operator+=(Duration o) {
    ns_ += o.ns_;
    return *this;
  }
  constexpr Duration& operator-=(Duration o) {
    ns_ -= o.ns_;
    return *this;
  }
  constexpr auto operator<=>(const Duration&) const = default;

  /// Human-readable form with a unit chosen by magnitude: "1.500 s", "250 us".
  std::string ToString() const;

 private:
  constexpr explicit Duration(int64_t ns) : ns_(ns) {}
  int64_t ns_ = 0;
};

constexpr Duration operator*(int64_t k, Duration d) { return d * k; }

/// A point on CLOCK_MONOTONIC, in integer nanoseconds since its epoch (boot).
class Time {
 public:
  constexpr Time() = default;

  static constexpr Time FromNanoseconds(int64_t ns) { return Time(ns); }
  /// Rounds to the nearest nanosecond.
  static Time FromSeconds(double seconds);
  static constexpr Time Zero() { return Time(0); }
  static constexpr Time Max() { return Time(std::numeric_limits<int64_t>::max()); }
  /// Reads CLOCK_MONOTONIC. Never blocks or allocates (vDSO).
  static Time Now();

  constexpr int64_t nanoseconds() const { return ns_; }
  constexpr double ToSeconds() const { return static_cast<double>(ns_) * 1e-9; }

  constexpr Time operator+(Duration d) const { return Time(ns_ + d.nanoseconds()); }
  constexpr Time operator-(Duration d) const { return Time(ns_ - d.nanoseconds()); }
  constexpr Duration operator-(Time o) const { return Duration::Nanoseconds(ns_ - o.ns_); }
  constexpr Time& operator+=(Duration d) {
    ns_ += d.nanoseconds();
    return *this;
  }
  constexpr Time& operator-=(Duration d) {
    ns_ -= d.nanoseconds();
    return *this;
  }
  constexpr auto operator<=>(const Time&) const = default;

  /// "12.345678901 s" (seconds since boot, full nanosecond precision).
  std::string ToString() const;

 private:
  constexpr explicit Time(int64_t ns) : ns_(ns) {}
  int64_t ns_ = 0;
};

}  // namespace rover

#endif  // ROVER_CORE_TIME_TIME_H_
