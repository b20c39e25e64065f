#include "drivers/gpio/gpio_camera_trigger.h"

#include <time.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "drivers/gpio/fake_gpio_chip.h"

namespace rover::drivers {
namespace {

using ::testing::HasSubstr;

constexpr uint32_t kLine = 17;

GpioCameraTriggerOptions Options(double rate_hz, Duration width) {
  GpioCameraTriggerOptions o;
  o.rate_hz = rate_hz;
  o.pulse_width = width;
  o.line = kLine;
  return o;
}

void SleepUntil(Time t) {
  const timespec ts{static_cast<time_t>(t.nanoseconds() / 1'000'000'000),
                    static_cast<long>(t.nanoseconds() % 1'000'000'000)};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) != 0) {
  }
}

// Timing assertions are on what the code controls exactly (the slot grid,
// the order and count of transitions, the minimum width); wall-clock spans
// only get a generous band because the machine is shared.
TEST(GpioCameraTriggerTest, PulsesAtTheRequestedRateAndWidth) {
  FakeGpioChip chip;
  const Duration width = Duration::Milliseconds(2);
  GpioCameraTrigger trigger(chip, Options(100.0, width));
  const Duration period = trigger.period();
  ASSERT_EQ(period, Duration::Milliseconds(10));
  constexpr int kPulses = 20;
  std::vector<Time> stamps;
  std::vector<Time> slots;
  for (int i = 0; i < kPulses; ++i) {
    Time stamp;
    ASSERT_EQ(trigger.Next(&stamp, Duration::Seconds(1)), ReadStatus::kOk);
    stamps.push_back(stamp);
    slots.push_back(trigger.last_deadline());
  }
  const auto t = chip.transitions(kLine);
  ASSERT_EQ(t.size(), 2U * kPulses);  // idle low at the request: no transition
  for (std::size_t i = 0; i < kPulses; ++i) {
    const auto& rise = t[2 * i];
    const auto& fall = t[2 * i + 1];
    EXPECT_TRUE(rise.high);
    EXPECT_FALSE(fall.high);
    // The pin changed inside Set(); the stamp is read right after it.
    EXPECT_GE(rise.stamp, slots[i]);
    EXPECT_LE(rise.stamp, stamps[i]);
    EXPECT_GE(fall.stamp - rise.stamp, width);
    if (i > 0) {
      EXPECT_GT(slots[i], slots[i - 1]);
      EXPECT_EQ((slots[i] - slots[i - 1]).nanoseconds() % period.nanoseconds(), 0);
    }
    EXPECT_EQ(slots[i].nanoseconds() % period.nanoseconds(), 0);  // phase 0
  }
  const GpioCameraTriggerStats& s = trigger.stats();
  EXPECT_EQ(s.pulses, static_cast<uint64_t>(kPulses));
  // Every slot between the first and the last pulse was either pulsed or
  // counted as skipped: no slot is lost and none doubled.
  const int64_t slots_spanned = (slots.back() - slots.front()).nanoseconds() / period.nanoseconds();
  EXPECT_EQ(static_cast<uint64_t>(slots_spanned), kPulses - 1 + s.skipped_pulses);
  const Duration span = stamps.back() - stamps.front();
  EXPECT_GT(span, period * slots_spanned - Duration::Milliseconds(50));
  EXPECT_LT(span, period * slots_spanned + Duration::Milliseconds(50));
  EXPECT_EQ(s.set_errors, 0U);
  EXPECT_EQ(chip.set_calls(kLine), 2U * kPulses);
}

TEST(GpioCameraTriggerTest, PhaseShiftsTheGrid) {
  FakeGpioChip chip;
  GpioCameraTriggerOptions o = Options(50.0, Duration::Milliseconds(1));
  o.phase = Duration::Microseconds(3300);
  GpioCameraTrigger trigger(chip, o);
  for (int i = 0; i < 3; ++i) {
    Time stamp;
    ASSERT_EQ(trigger.Next(&stamp, Duration::Seconds(1)), ReadStatus::kOk);
    EXPECT_EQ(trigger.last_deadline().nanoseconds() % Duration::Milliseconds(20).nanoseconds(),
              Duration::Microseconds(3300).nanoseconds());
    EXPECT_GE(stamp, trigger.last_deadline());
  }
}

TEST(GpioCameraTriggerTest, ActiveLowPulsesGoLow) {
  FakeGpioChip chip;
  GpioCameraTriggerOptions o = Options(100.0, Duration::Milliseconds(1));
  o.active_low = true;
  GpioCameraTrigger trigger(chip, o);
  Time stamp;
  ASSERT_EQ(trigger.Next(&stamp, Duration::Seconds(1)), ReadStatus::kOk);
  ASSERT_EQ(trigger.Next(&stamp, Duration::Seconds(1)), ReadStatus::kOk);
  const auto t = chip.transitions(kLine);
  ASSERT_EQ(t.size(), 5U);
  EXPECT_TRUE(t[0].high);  // idle level set by the request
  EXPECT_FALSE(t[1].high);
  EXPECT_TRUE(t[2].high);
  EXPECT_FALSE(t[3].high);
  EXPECT_TRUE(t[4].high);
}

TEST(GpioCameraTriggerTest, ALateCallerSkipsSlotsInsteadOfBursting) {
  FakeGpioChip chip;
  GpioCameraTrigger trigger(chip, Options(100.0, Duration::Milliseconds(1)));
  const Duration period = trigger.period();
  Time first;
  ASSERT_EQ(trigger.Next(&first, Duration::Seconds(1)), ReadStatus::kOk);
  const Time first_slot = trigger.last_deadline();
  // The camera thread stalls for five and a half periods.
  SleepUntil(first_slot + period * 11 / 2);
  const Time resumed = Time::Now();
  Time second;
  ASSERT_EQ(trigger.Next(&second, Duration::Seconds(1)), ReadStatus::kOk);
  const Time second_slot = trigger.last_deadline();
  // The slot is in the future of the resumed caller: nothing fired back to back.
  EXPECT_GE(second_slot, resumed);
  EXPECT_GE(second_slot - first_slot, period * 6);
  EXPECT_EQ(static_cast<uint64_t>((second_slot - first_slot) / period) - 1,
            trigger.stats().skipped_pulses);
  EXPECT_GE(trigger.stats().skipped_pulses, 5U);
  EXPECT_EQ(trigger.stats().late_pulses, 0U);
  EXPECT_EQ(chip.transitions(kLine).size(), 4U);
}

TEST(GpioCameraTriggerTest, ASlightlyLateCallerStillGetsItsPulse) {
  FakeGpioChip chip;
  // 1 Hz: a quarter period is 250 ms of margin for a noisy machine.
  GpioCameraTrigger trigger(chip, Options(1.0, Duration::Milliseconds(1)));
  Time stamp;
  ASSERT_EQ(trigger.Next(&stamp, Duration::Seconds(3)), ReadStatus::kOk);
  const Time first_slot = trigger.last_deadline();
  SleepUntil(first_slot + trigger.period() + Duration::Milliseconds(5));
  ASSERT_EQ(trigger.Next(&stamp, Duration::Seconds(3)), ReadStatus::kOk);
  EXPECT_EQ(trigger.last_deadline(), first_slot + trigger.period());
  EXPECT_EQ(trigger.stats().late_pulses, 1U);
  EXPECT_EQ(trigger.stats().skipped_pulses, 0U);
}

TEST(GpioCameraTriggerTest, ATimeoutShorterThanThePulseEmitsNothing) {
  FakeGpioChip chip;
  GpioCameraTrigger trigger(chip, Options(10.0, Duration::Milliseconds(1)));
  Time stamp;
  EXPECT_EQ(trigger.Next(&stamp, Duration::Microseconds(500)), ReadStatus::kTimeout);
  EXPECT_EQ(trigger.Next(&stamp, Duration::Zero()), ReadStatus::kTimeout);
  EXPECT_EQ(trigger.stats().timeouts, 2U);
  EXPECT_EQ(trigger.stats().pulses, 0U);
  EXPECT_TRUE(chip.transitions(kLine).empty());
  EXPECT_EQ(trigger.Next(&stamp, Duration::Seconds(1)), ReadStatus::kOk);
}

TEST(GpioCameraTriggerTest, RefusedSetsAreErrorsAndCounted) {
  FakeGpioChip chip;
  GpioCameraTrigger trigger(chip, Options(100.0, Duration::Milliseconds(1)));
  chip.FailNextSets(kLine, 1);
  Time stamp;
  EXPECT_EQ(trigger.Next(&stamp, Duration::Seconds(1)), ReadStatus::kError);
  EXPECT_EQ(trigger.stats().set_errors, 1U);
  EXPECT_EQ(trigger.Next(&stamp, Duration::Seconds(1)), ReadStatus::kOk);
  EXPECT_EQ(trigger.stats().pulses, 1U);
  EXPECT_EQ(chip.transitions(kLine).size(), 2U);
}

TEST(GpioCameraTriggerTest, DestructionLeavesTheLineInactiveAndFree) {
  FakeGpioChip chip;
  {
    GpioCameraTrigger trigger(chip, Options(100.0, Duration::Milliseconds(1)));
    EXPECT_TRUE(chip.requested(kLine));
  }
  EXPECT_FALSE(chip.requested(kLine));
  EXPECT_FALSE(chip.physical_level(kLine));
}

TEST(GpioCameraTriggerTest, OptionsAreValidatedNamingTheField) {
  const auto message = [](const GpioCameraTriggerOptions& o) -> std::string {
    try {
      o.Validate();
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  GpioCameraTriggerOptions o = Options(0.0, Duration::Milliseconds(1));
  EXPECT_THAT(message(o), HasSubstr("rate_hz: expected 1 to 100, found 0"));
  o.rate_hz = 101.0;
  EXPECT_THAT(message(o), HasSubstr("rate_hz"));
  o.rate_hz = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THAT(message(o), HasSubstr("rate_hz"));
  o.rate_hz = 10.0;
  EXPECT_EQ(message(o), "");
  o.phase = Duration::Milliseconds(100);
  EXPECT_THAT(message(o), HasSubstr("phase: expected [0, 100.000 ms)"));
  o.phase = Duration::Zero();
  o.pulse_width = Duration::Milliseconds(100);
  EXPECT_THAT(message(o), HasSubstr("pulse_width"));
  o.pulse_width = Duration::Zero();
  EXPECT_THAT(message(o), HasSubstr("pulse_width"));
  o.pulse_width = Duration::Milliseconds(1);
  o.consumer = "";
  EXPECT_THAT(message(o), HasSubstr("consumer"));

  FakeGpioChip chip;
  EXPECT_THROW(GpioCameraTrigger(chip, Options(500.0, Duration::Milliseconds(1))),
               std::invalid_argument);
  EXPECT_FALSE(chip.requested(kLine));
}

TEST(GpioCameraTriggerTest, ABusyLineIsAStartUpErrorNamingChipAndLine) {
  FakeGpioChip chip("trigger-chip");
  GpioCameraTrigger first(chip, Options(10.0, Duration::Milliseconds(1)));
  try {
    GpioCameraTrigger second(chip, Options(10.0, Duration::Milliseconds(1)));
    FAIL() << "expected GpioError";
  } catch (const GpioError& e) {
    EXPECT_THAT(e.what(), HasSubstr("trigger-chip line 17"));
    EXPECT_THAT(e.what(), HasSubstr("rover-camera-trigger"));
  }
}

}  // namespace
}  // namespace rover::drivers
