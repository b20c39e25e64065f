#include "core/time/realtime_to_monotonic.h"

#include <time.h>

#include <gtest/gtest.h>

namespace rover {
namespace {

int64_t RealtimeNowNs() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}

// A realtime stamp taken now converts to (about) monotonic now, and a stamp
// 5 ms in the past to 5 ms before it: the offset is applied, not re-derived
// from the stamp.
TEST(RealtimeToMonotonicTest, MovesRealtimeStampsOntoTheMonotonicClock) {
  RealtimeToMonotonic convert;
  const Time before = Time::Now();
  const int64_t real = RealtimeNowNs();
  const Time after = Time::Now();
  const Time mono = convert.ToMonotonic(real);
  // Generous: a preempted read is tolerated by the converter, not here.
  EXPECT_GT(mono, before - Duration::Milliseconds(20));
  EXPECT_LT(mono, after + Duration::Milliseconds(20));
  EXPECT_EQ(convert.ToMonotonic(real - 5'000'000), mono - Duration::Milliseconds(5));
}

// Within the refresh period the offset is not re-read, so conversions are
// exactly consistent with each other; it is set by the first call.
TEST(RealtimeToMonotonicTest, OffsetIsHeldBetweenRefreshes) {
  RealtimeToMonotonic convert(Duration::Microseconds(50), Duration::Seconds(3600));
  EXPECT_EQ(convert.offset(), Duration::Zero());
  const Time a = convert.ToMonotonic(1'000'000'000);
  const Duration offset = convert.offset();
  EXPECT_NE(offset, Duration::Zero());
  EXPECT_EQ(a, Time::FromNanoseconds(1'000'000'000) - offset);
  for (int i = 0; i < 100; ++i) convert.ToMonotonic(RealtimeNowNs());
  EXPECT_EQ(convert.offset(), offset);
}

// Even a bracket no read can meet yields an offset on the first call (the
// last of its attempts), and keeps it afterwards.
TEST(RealtimeToMonotonicTest, AnImpossibleBracketStillGivesAFirstOffset) {
  RealtimeToMonotonic convert(Duration::Nanoseconds(-1), Duration::Zero());
  const Time mono = convert.ToMonotonic(RealtimeNowNs());
  EXPECT_NE(convert.offset(), Duration::Zero());
  const Duration first = convert.offset();
  EXPECT_LT(mono - Time::Now(), Duration::Milliseconds(20));
  convert.ToMonotonic(RealtimeNowNs());
  EXPECT_EQ(convert.offset(), first);
}

}  // namespace
}  // namespace rover
