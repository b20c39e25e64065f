#include "drivers/gpio/gpio_line_edge_source.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>
#include <stdexcept>
#include <vector>

#include "drivers/gpio/fake_gpio_chip.h"

namespace rover::drivers {
namespace {

using ::testing::HasSubstr;

constexpr uint32_t kLine = 27;
const Time kT0 = Time::FromNanoseconds(5'000'000'000);
const Duration kPeriod = Duration::Milliseconds(10);  // a 100 Hz data-ready line
const Duration kWidth = Duration::Microseconds(50);

GpioLineEdgeSourceOptions Options(GpioEdges edges, Duration period) {
  GpioLineEdgeSourceOptions o;
  o.line = kLine;
  o.edges = edges;
  o.nominal_period = period;
  return o;
}

// Reads everything queued; returns the edges in order.
std::vector<GpioEdge> Drain(GpioLineEdgeSource* source) {
  std::vector<GpioEdge> edges;
  GpioEdge edge;
  while (source->Wait(&edge, Duration::Zero()) == ReadStatus::kOk) edges.push_back(edge);
  return edges;
}

// Injects pulse k of a periodic train: rising at k periods, falling a width later.
void Pulse(FakeGpioChip* chip, int k, bool rise = true, bool fall = true) {
  const Time t = kT0 + kPeriod * k;
  if (rise) chip->InjectEdge(kLine, t, true);
  if (fall) chip->InjectEdge(kLine, t + kWidth, false);
}

TEST(GpioLineEdgeSourceTest, DeliversEdgesWithTheKernelStamps) {
  FakeGpioChip chip;
  GpioLineEdgeSource source(chip, Options(GpioEdges::kBoth, kPeriod));
  for (int k = 0; k < 5; ++k) Pulse(&chip, k);
  const std::vector<GpioEdge> edges = Drain(&source);
  ASSERT_EQ(edges.size(), 10U);
  for (int k = 0; k < 5; ++k) {
    const GpioEdge& rise = edges[static_cast<std::size_t>(2 * k)];
    const GpioEdge& fall = edges[static_cast<std::size_t>(2 * k + 1)];
    EXPECT_EQ(rise.stamp, kT0 + kPeriod * k);
    EXPECT_TRUE(rise.rising);
    EXPECT_EQ(rise.line, kLine);
    EXPECT_EQ(fall.stamp, kT0 + kPeriod * k + kWidth);
    EXPECT_FALSE(fall.rising);
  }
  EXPECT_EQ(source.stats().edges, 10U);
  EXPECT_EQ(source.lost_edges(), 0U);
  EXPECT_EQ(source.stats().timeouts, 1U);  // Drain's last call
}

TEST(GpioLineEdgeSourceTest, PatternFindsAMissingFallingEdgeWithoutAPeriod) {
  FakeGpioChip chip;
  GpioLineEdgeSource source(chip, Options(GpioEdges::kBoth, Duration::Zero()));
  Pulse(&chip, 0);
  Pulse(&chip, 1, true, false);  // falling edge lost
  Pulse(&chip, 2);
  EXPECT_EQ(Drain(&source).size(), 5U);
  EXPECT_EQ(source.lost_edges(), 1U);
}

TEST(GpioLineEdgeSourceTest, PatternFindsAMissingRisingEdgeWithoutAPeriod) {
  FakeGpioChip chip;
  GpioLineEdgeSource source(chip, Options(GpioEdges::kBoth, Duration::Zero()));
  Pulse(&chip, 0);
  Pulse(&chip, 1, false, true);  // rising edge lost
  Pulse(&chip, 2);
  Drain(&source);
  EXPECT_EQ(source.lost_edges(), 1U);
}

TEST(GpioLineEdgeSourceTest, PatternAndPeriodNeverCountAnEdgeTwice) {
  FakeGpioChip chip;
  GpioLineEdgeSource source(chip, Options(GpioEdges::kBoth, kPeriod));
  Pulse(&chip, 0);
  Pulse(&chip, 1, false, true);  // rising lost: falling after falling
  Pulse(&chip, 2);
  Pulse(&chip, 3, true, false);  // falling lost: rising after rising
  Pulse(&chip, 4);
  Pulse(&chip, 5, false, false);  // a whole pulse lost: only the period shows it
  Pulse(&chip, 6);
  Drain(&source);
  EXPECT_EQ(source.lost_edges(), 4U);
}

TEST(GpioLineEdgeSourceTest, PeriodGapCountsMissingEdgesOfASingleKind) {
  FakeGpioChip chip;
  GpioLineEdgeSource source(chip, Options(GpioEdges::kRising, kPeriod));
  for (int k : {0, 1, 2, 5, 6, 10}) Pulse(&chip, k);
  EXPECT_EQ(Drain(&source).size(), 6U);  // falling edges never reach the FIFO
  EXPECT_EQ(source.lost_edges(), 2U + 3U);
}

TEST(GpioLineEdgeSourceTest, JitterAndGlitchesAreNotLosses) {
  FakeGpioChip chip;
  GpioLineEdgeSource source(chip, Options(GpioEdges::kBoth, kPeriod));
  chip.InjectEdge(kLine, kT0, true);
  chip.InjectEdge(kLine, kT0 + kWidth, false);
  // 1.4 periods later (jitter), then a glitch pulse half a period later.
  const Time t1 = kT0 + Duration::Milliseconds(14);
  chip.InjectEdge(kLine, t1, true);
  chip.InjectEdge(kLine, t1 + kWidth, false);
  chip.InjectEdge(kLine, t1 + Duration::Milliseconds(5), true);
  chip.InjectEdge(kLine, t1 + Duration::Milliseconds(5) + kWidth, false);
  Drain(&source);
  EXPECT_EQ(source.lost_edges(), 0U);
}

TEST(GpioLineEdgeSourceTest, FifoOverflowIsCountedFromThePeriod) {
  FakeGpioChip chip;
  GpioLineEdgeSource source(chip, Options(GpioEdges::kBoth, kPeriod));
  // The reader stalls for 20 pulses: the kernel keeps the first 16 events
  // and drops the other 24, with no trace in the events themselves.
  for (int k = 0; k < 20; ++k) Pulse(&chip, k);
  EXPECT_EQ(chip.dropped_events(kLine), 24U);
  EXPECT_EQ(Drain(&source).size(), 16U);
  // The reader is back; the next pulses arrive normally.
  for (int k = 20; k < 23; ++k) Pulse(&chip, k);
  EXPECT_EQ(Drain(&source).size(), 6U);
  EXPECT_EQ(source.lost_edges(), chip.dropped_events(kLine));
}

TEST(GpioLineEdgeSourceTest, FifoOverflowOfAnOddCountShowsInThePatternAlone) {
  FakeGpioChip chip;
  GpioLineEdgeSource source(chip, Options(GpioEdges::kBoth, Duration::Zero()));
  for (int k = 0; k < 8; ++k) Pulse(&chip, k);      // fills the FIFO exactly
  chip.InjectEdge(kLine, kT0 + kPeriod * 8, true);  // dropped
  Drain(&source);
  Pulse(&chip, 9, false, true);  // falling after falling
  Pulse(&chip, 10);
  Drain(&source);
  EXPECT_EQ(chip.dropped_events(kLine), 1U);
  EXPECT_EQ(source.lost_edges(), 1U);
}

// A long seeded train with jitter and random losses: with a period the
// estimate is exact.
TEST(GpioLineEdgeSourceTest, RandomLossesAreCountedExactly) {
  std::mt19937 rng(42);
  std::uniform_int_distribution<int64_t> jitter_us(-2000, 2000);  // ±20 % of a period
  std::bernoulli_distribution lose(0.08);
  FakeGpioChip chip;
  GpioLineEdgeSource source(chip, Options(GpioEdges::kBoth, kPeriod));
  uint64_t removed = 0;
  GpioEdge edge;
  for (int k = 0; k < 2000; ++k) {
    // Never lose the first and last pulses: losses are only visible between edges.
    const bool keep_rise = k == 0 || k == 1999 || !lose(rng);
    const bool keep_fall = k == 0 || k == 1999 || !lose(rng);
    removed += (keep_rise ? 0U : 1U) + (keep_fall ? 0U : 1U);
    const Time t = kT0 + kPeriod * k + Duration::Microseconds(jitter_us(rng));
    if (keep_rise) chip.InjectEdge(kLine, t, true);
    if (keep_fall) chip.InjectEdge(kLine, t + Duration::Milliseconds(2), false);
    while (source.Wait(&edge, Duration::Zero()) == ReadStatus::kOk) {
    }
  }
  EXPECT_EQ(chip.dropped_events(kLine), 0U);
  EXPECT_EQ(source.lost_edges(), removed);
  EXPECT_EQ(source.stats().edges, 4000U - removed);
}

TEST(GpioLineEdgeSourceTest, TimeoutsReadErrorsAndBackwardStampsAreCounted) {
  FakeGpioChip chip;
  GpioLineEdgeSource source(chip, Options(GpioEdges::kBoth, Duration::Zero()));
  GpioEdge edge;
  EXPECT_EQ(source.Wait(&edge, Duration::Milliseconds(1)), ReadStatus::kTimeout);
  chip.FailNextReads(kLine, 2);
  EXPECT_EQ(source.Wait(&edge, Duration::Zero()), ReadStatus::kError);
  EXPECT_EQ(source.Wait(&edge, Duration::Zero()), ReadStatus::kError);
  chip.InjectEdge(kLine, kT0, true);
  chip.InjectEdge(kLine, kT0 - Duration::Microseconds(1), false);
  Drain(&source);
  EXPECT_EQ(source.stats().timeouts, 2U);
  EXPECT_EQ(source.stats().read_errors, 2U);
  EXPECT_EQ(source.stats().backward_stamps, 1U);
}

TEST(GpioLineEdgeSourceTest, OptionsAreValidated) {
  FakeGpioChip chip;
  GpioLineEdgeSourceOptions o = Options(GpioEdges::kBoth, Duration::Milliseconds(-1));
  try {
    GpioLineEdgeSource source(chip, o);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("nominal_period"));
    EXPECT_THAT(e.what(), HasSubstr("expected >= 0"));
  }
  o.nominal_period = Duration::Zero();
  o.consumer = std::string(32, 'x');
  EXPECT_THROW(o.Validate(), std::invalid_argument);
  o.consumer = "";
  EXPECT_THROW(o.Validate(), std::invalid_argument);
  EXPECT_FALSE(chip.requested(kLine));  // nothing was requested on a failed validation
}

TEST(GpioLineEdgeSourceTest, ABusyLineIsAStartUpErrorNamingChipAndLine) {
  FakeGpioChip chip("imu-chip");
  GpioLineEdgeSource first(chip, Options(GpioEdges::kBoth, kPeriod));
  try {
    GpioLineEdgeSource second(chip, Options(GpioEdges::kRising, kPeriod));
    FAIL() << "expected GpioError";
  } catch (const GpioError& e) {
    EXPECT_THAT(e.what(), HasSubstr("imu-chip line 27"));
  }
}

}  // namespace
}  // namespace rover::drivers
