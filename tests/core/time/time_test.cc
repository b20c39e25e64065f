#include "core/time/time.h"

#include <gtest/gtest.h>

#include <type_traits>

namespace rover {
namespace {

static_assert(std::is_trivially_copyable_v<Time>);
static_assert(std::is_trivially_copyable_v<Duration>);
static_assert(sizeof(Time) == 8 && sizeof(Duration) == 8);
// A point plus a point is meaningless and must not compile.
template <typename A, typename B>
concept Addable = requires(A a, B b) {
  a + b;
};
static_assert(!Addable<Time, Time>);
static_assert(Addable<Time, Duration>);

TEST(DurationTest, ConversionsAreExact) {
  EXPECT_EQ(Duration::Seconds(2).nanoseconds(), 2'000'000'000);
  EXPECT_EQ(Duration::Milliseconds(3).nanoseconds(), 3'000'000);
  EXPECT_EQ(Duration::Microseconds(7).nanoseconds(), 7'000);
  EXPECT_EQ(Duration::FromSeconds(0.0025).nanoseconds(), 2'500'000);
  EXPECT_EQ(Duration::FromSeconds(-1e-9).nanoseconds(), -1);
  EXPECT_DOUBLE_EQ(Duration::Milliseconds(1500).ToSeconds(), 1.5);
}

TEST(DurationTest, Arithmetic) {
  const Duration a = Duration::Milliseconds(10);
  const Duration b = Duration::Milliseconds(4);
  EXPECT_EQ((a - b).nanoseconds(), 6'000'000);
  EXPECT_EQ((a + b).nanoseconds(), 14'000'000);
  EXPECT_EQ((3 * b).nanoseconds(), 12'000'000);
  EXPECT_EQ((a / 4).nanoseconds(), 2'500'000);
  EXPECT_DOUBLE_EQ(b / a, 0.4);
  EXPECT_LT(b, a);
  EXPECT_EQ((-a).nanoseconds(), -10'000'000);
}

TEST(DurationTest, FormatsWithUnitByMagnitude) {
  EXPECT_EQ(Duration::Milliseconds(1500).ToString(), "1.500 s");
  EXPECT_EQ(Duration::Microseconds(2500).ToString(), "2.500 ms");
  EXPECT_EQ(Duration::Nanoseconds(2500).ToString(), "2.500 us");
  EXPECT_EQ(Duration::Nanoseconds(-12).ToString(), "-12 ns");
}

TEST(TimeTest, PointArithmetic) {
  const Time t0 = Time::FromNanoseconds(1'000);
  const Time t1 = t0 + Duration::Microseconds(2);
  EXPECT_EQ(t1.nanoseconds(), 3'000);
  EXPECT_EQ((t1 - t0).nanoseconds(), 2'000);
  EXPECT_EQ((t1 - Duration::Nanoseconds(500)).nanoseconds(), 2'500);
  EXPECT_GT(t1, t0);
  EXPECT_EQ(Time::FromSeconds(1.25).nanoseconds(), 1'250'000'000);
}

TEST(TimeTest, FormatsFullPrecision) {
  EXPECT_EQ(Time::FromNanoseconds(12'345'678'901).ToString(), "12.345678901 s");
  EXPECT_EQ(Time::FromNanoseconds(-500'000'000).ToString(), "-0.500000000 s");
}

TEST(TimeTest, NowIsMonotonic) {
  Time prev = Time::Now();
  for (int i = 0; i < 1000; ++i) {
    const Time now = Time::Now();
    ASSERT_GE(now, prev);
    prev = now;
  }
  EXPECT_GT(prev.nanoseconds(), 0);
}

}  // namespace
}  // namespace rover
