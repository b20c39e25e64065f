#include "firmware/runtime/rt/periodic_timer.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <stdexcept>

#include "tests/support/allocation_counter.h"

namespace rover::runtime {
namespace {

// A clock that only moves when told to: SleepUntil jumps to the deadline
// plus a fixed wake-up latency.
class FakeClock final : public PeriodicTimer::Clock {
 public:
  Time Now() override { return now_; }
  void SleepUntil(Time deadline) override {
    ++sleeps_;
    if (deadline > now_) now_ = deadline;
    now_ += wake_latency_;
  }
  void Advance(Duration d) { now_ += d; }
  void set_wake_latency(Duration d) { wake_latency_ = d; }
  int sleeps() const { return sleeps_; }

 private:
  Time now_ = Time::FromNanoseconds(0);
  Duration wake_latency_;
  int sleeps_ = 0;
};

constexpr Duration kPeriod = Duration::Milliseconds(1);

TEST(PeriodicTimerTest, OnTimeLoopServesEverySlot) {
  FakeClock clock;
  clock.set_wake_latency(Duration::Microseconds(7));
  PeriodicTimer timer(kPeriod, Time::FromNanoseconds(0) + kPeriod, clock);
  for (int64_t k = 0; k < 5; ++k) {
    const PeriodicTimer::Tick tick = timer.WaitNext();
    EXPECT_EQ(tick.index, k);
    EXPECT_EQ(tick.deadline, Time::FromNanoseconds(0) + kPeriod * (k + 1));
    EXPECT_EQ(tick.woke - tick.deadline, Duration::Microseconds(7));
    EXPECT_EQ(tick.missed_periods, 0u);
    EXPECT_TRUE(tick.slept);
    clock.Advance(Duration::Microseconds(100));  // work well inside the period
  }
  EXPECT_EQ(timer.ticks(), 5u);
  EXPECT_EQ(timer.missed_periods(), 0u);
  EXPECT_EQ(clock.sleeps(), 5);
}

TEST(PeriodicTimerTest, OverrunSkipsPassedSlotsWithoutBurstAndKeepsPhase) {
  FakeClock clock;
  PeriodicTimer timer(kPeriod, Time::FromNanoseconds(0) + kPeriod, clock);
  PeriodicTimer::Tick tick = timer.WaitNext();  // slot 0 at 1 ms
  ASSERT_EQ(tick.index, 0);
  clock.Advance(Duration::Microseconds(3'500));  // work overruns to 4.5 ms

  tick = timer.WaitNext();  // slots 1 (2 ms), 2 (3 ms) missed; slot 3 (4 ms) served at once
  EXPECT_EQ(tick.index, 3);
  EXPECT_EQ(tick.missed_periods, 2u);
  EXPECT_EQ(tick.deadline, Time::FromNanoseconds(4'000'000));
  EXPECT_EQ(tick.woke, Time::FromNanoseconds(4'500'000));
  EXPECT_FALSE(tick.slept);
  EXPECT_EQ(clock.sleeps(), 1);  // no sleep for a late slot

  tick = timer.WaitNext();  // back on the original grid: slot 4 at 5 ms, slept for
  EXPECT_EQ(tick.index, 4);
  EXPECT_EQ(tick.missed_periods, 0u);
  EXPECT_EQ(tick.deadline, Time::FromNanoseconds(5'000'000));
  EXPECT_TRUE(tick.slept);
  EXPECT_EQ(clock.sleeps(), 2);

  EXPECT_EQ(timer.ticks(), 3u);
  EXPECT_EQ(timer.missed_periods(), 2u);
  EXPECT_EQ(timer.ticks() + timer.missed_periods(), static_cast<uint64_t>(tick.index) + 1);
}

TEST(PeriodicTimerTest, ReturningExactlyAtTheDeadlineIsNotAMiss) {
  FakeClock clock;
  PeriodicTimer timer(kPeriod, Time::FromNanoseconds(0) + kPeriod, clock);
  timer.WaitNext();
  clock.Advance(kPeriod);  // now == next deadline
  const PeriodicTimer::Tick tick = timer.WaitNext();
  EXPECT_EQ(tick.index, 1);
  EXPECT_EQ(tick.missed_periods, 0u);
  EXPECT_FALSE(tick.slept);  // served at once: no wake-up to measure
}

TEST(PeriodicTimerTest, CountersStayConsistentUnderRandomOverruns) {
  FakeClock clock;
  clock.set_wake_latency(Duration::Microseconds(20));
  const Time first = Time::FromNanoseconds(123'456);
  PeriodicTimer timer(kPeriod, first, clock);
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<int64_t> work_us(0, 4'000);
  int64_t previous_index = -1;
  for (int i = 0; i < 10'000; ++i) {
    const PeriodicTimer::Tick tick = timer.WaitNext();
    ASSERT_GT(tick.index, previous_index);
    ASSERT_EQ(tick.deadline, first + kPeriod * tick.index);
    ASSERT_GE(tick.woke, tick.deadline);
    // The slot served is the latest one that had passed: no catch-up burst.
    ASSERT_LT(tick.woke - tick.deadline, kPeriod + Duration::Microseconds(20));
    ASSERT_EQ(tick.missed_periods, static_cast<uint64_t>(tick.index - previous_index - 1));
    if (tick.missed_periods > 0) {
      ASSERT_FALSE(tick.slept);
    }
    ASSERT_EQ(timer.ticks() + timer.missed_periods(), static_cast<uint64_t>(tick.index) + 1);
    previous_index = tick.index;
    clock.Advance(Duration::Microseconds(work_us(rng)));
  }
  EXPECT_GT(timer.missed_periods(), 0u);
}

TEST(PeriodicTimerTest, RealClockCountsEveryElapsedPeriod) {
  // Short period with deliberate overruns. Only counter consistency is
  // asserted, never how long anything took.
  constexpr Duration kShort = Duration::Microseconds(100);
  PeriodicTimer timer(kShort);
  const Time first = timer.first_deadline();
  PeriodicTimer::Tick tick;
  int overruns = 0;
  for (int i = 0; i < 400; ++i) {
    tick = timer.WaitNext();
    ASSERT_GE(tick.woke, tick.deadline);
    if (i % 50 == 10) {
      ++overruns;
      const Time until = Time::Now() + Duration::Microseconds(350);
      while (Time::Now() < until) {
      }
    }
  }
  EXPECT_EQ(timer.ticks(), 400u);
  EXPECT_EQ(timer.ticks() + timer.missed_periods(), static_cast<uint64_t>(tick.index) + 1);
  // Each 350 us overrun of a 100 us period skips at least 2 slots.
  EXPECT_GE(timer.missed_periods(), 2u * static_cast<uint64_t>(overruns));
  // Slots elapsed by the last wake-up: at least the ones accounted for.
  const int64_t elapsed = (tick.woke - first).nanoseconds() / kShort.nanoseconds() + 1;
  EXPECT_GE(elapsed, tick.index + 1);
}

TEST(PeriodicTimerTest, WaitNextNeverAllocates) {
  FakeClock clock;
  PeriodicTimer timer(kPeriod, Time::FromNanoseconds(0) + kPeriod, clock);
  testing::ScopedAllocationCheck check;
  for (int i = 0; i < 1000; ++i) {
    timer.WaitNext();
    clock.Advance(Duration::Microseconds(i % 7 == 0 ? 2'500 : 10));
  }
  EXPECT_EQ(check.allocations(), 0u);
}

TEST(PeriodicTimerTest, NonPositivePeriodIsRejected) {
  FakeClock clock;
  try {
    PeriodicTimer timer(Duration::Zero(), Time::FromNanoseconds(0), clock);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "PeriodicTimer: expected a positive period, found 0 ns");
  }
}

}  // namespace
}  // namespace rover::runtime
