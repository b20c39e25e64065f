#include "drivers/gpio/gpio_loopback_check.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <stdexcept>

#include "drivers/gpio/fake_gpio_chip.h"

namespace rover::drivers {
namespace {

using ::testing::HasSubstr;

GpioLoopbackOptions Options() {
  GpioLoopbackOptions o;
  o.output_line = 17;
  o.input_line = 27;
  o.pulses = 10;
  o.rate_hz = 50.0;
  o.pulse_width = Duration::Milliseconds(1);
  o.edge_timeout = Duration::Milliseconds(20);
  return o;
}

TEST(GpioLoopbackCheckTest, AWiredPairPassesWithTheWireDelayAsLatency) {
  FakeGpioChip chip;
  const Duration wire = Duration::Microseconds(20);
  chip.Connect(17, 27, wire);
  const GpioLoopbackReport report = GpioLoopbackCheck(chip, chip, Options()).Run();
  EXPECT_TRUE(report.passed()) << report.ToString();
  EXPECT_EQ(report.pulses, 10U);
  EXPECT_EQ(report.rising_edges, 10U);
  EXPECT_EQ(report.falling_edges, 10U);
  EXPECT_EQ(report.missing_edges, 0U);
  EXPECT_EQ(report.unexpected_edges, 0U);
  EXPECT_EQ(report.lost_edges, 0U);
  // The edge is stamped at the pin change plus the wire; the trigger stamps
  // after Set() returned, so the latency never exceeds the wire delay.
  EXPECT_LE(report.latency_max, wire);
  EXPECT_LE(report.latency_min, report.latency_p50);
  EXPECT_LE(report.latency_p50, report.latency_p99);
  EXPECT_LE(report.latency_p99, report.latency_max);
  EXPECT_GE(report.width_min, Duration::Milliseconds(1));
  EXPECT_THAT(report.ToString(), HasSubstr("PASS"));
  EXPECT_FALSE(chip.requested(17));
  EXPECT_FALSE(chip.requested(27));
}

TEST(GpioLoopbackCheckTest, ActiveLowWiringPasses) {
  FakeGpioChip chip;
  chip.Connect(17, 27);
  GpioLoopbackOptions o = Options();
  o.active_low = true;
  o.pulses = 4;
  const GpioLoopbackReport report = GpioLoopbackCheck(chip, chip, o).Run();
  EXPECT_TRUE(report.passed()) << report.ToString();
  EXPECT_EQ(report.rising_edges, 4U);
}

TEST(GpioLoopbackCheckTest, AMissingWireFailsWithEveryEdgeMissing) {
  FakeGpioChip chip;
  GpioLoopbackOptions o = Options();
  o.pulses = 3;
  o.edge_timeout = Duration::Milliseconds(2);
  const GpioLoopbackReport report = GpioLoopbackCheck(chip, chip, o).Run();
  EXPECT_FALSE(report.passed());
  EXPECT_EQ(report.pulses, 3U);
  EXPECT_EQ(report.missing_edges, 6U);
  EXPECT_THAT(report.ToString(), HasSubstr("FAIL: missing edges"));
}

TEST(GpioLoopbackCheckTest, LatencyAboveTheLimitFails) {
  FakeGpioChip chip;
  chip.Connect(17, 27, Duration::Microseconds(400));
  GpioLoopbackOptions o = Options();
  o.pulses = 3;
  o.max_latency = Duration::Microseconds(100);
  const GpioLoopbackReport report = GpioLoopbackCheck(chip, chip, o).Run();
  EXPECT_EQ(report.missing_edges, 0U);
  EXPECT_FALSE(report.passed());
  EXPECT_THAT(report.ToString(), HasSubstr("latency above 100.0 us"));
}

TEST(GpioLoopbackCheckTest, OptionsAreValidated) {
  FakeGpioChip chip;
  GpioLoopbackOptions o = Options();
  o.input_line = o.output_line;
  EXPECT_THROW(GpioLoopbackCheck(chip, chip, o), std::invalid_argument);
  o = Options();
  o.pulses = 0;
  EXPECT_THROW(GpioLoopbackCheck(chip, chip, o), std::invalid_argument);
  o = Options();
  o.rate_hz = 1000.0;
  try {
    GpioLoopbackCheck check(chip, chip, o);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("rate_hz"));
  }
}

}  // namespace
}  // namespace rover::drivers
