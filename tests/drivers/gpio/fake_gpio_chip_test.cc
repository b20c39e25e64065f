#include "drivers/gpio/fake_gpio_chip.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace rover::drivers {
namespace {

using ::testing::HasSubstr;

const Time kT0 = Time::FromNanoseconds(1'000'000'000);

TEST(FakeGpioChipTest, OutputRecordsPhysicalChangesOnly) {
  FakeGpioChip chip;
  auto out = chip.RequestOutput({3, "test", false}, false);
  EXPECT_TRUE(out->Set(true));
  EXPECT_TRUE(out->Set(true));  // no change: no transition
  EXPECT_TRUE(out->Set(false));
  const auto t = chip.transitions(3);
  ASSERT_EQ(t.size(), 2U);
  EXPECT_TRUE(t[0].high);
  EXPECT_FALSE(t[1].high);
  EXPECT_LE(t[0].stamp, t[1].stamp);
  EXPECT_EQ(chip.set_calls(3), 3U);
}

TEST(FakeGpioChipTest, ActiveLowOutputIdlesHighFromTheRequest) {
  FakeGpioChip chip;
  auto out = chip.RequestOutput({5, "test", true}, false);
  EXPECT_TRUE(chip.physical_level(5));
  out->Set(true);
  const auto t = chip.transitions(5);
  ASSERT_EQ(t.size(), 2U);
  EXPECT_TRUE(t[0].high);   // the request drove the idle (inactive) level
  EXPECT_FALSE(t[1].high);  // active = low
}

TEST(FakeGpioChipTest, FifoKeepsSixteenEventsAndDropsTheNewest) {
  FakeGpioChip chip;
  auto in = chip.RequestEdges({4, "test", false}, GpioEdges::kBoth);
  for (int i = 0; i < 20; ++i) {
    const bool queued = chip.InjectEdge(4, kT0 + Duration::Microseconds(i), i % 2 == 0);
    EXPECT_EQ(queued, i < 16) << i;
  }
  EXPECT_EQ(chip.dropped_events(4), 4U);
  EXPECT_EQ(chip.queued_events(4), 16U);
  GpioEdge edge;
  for (int i = 0; i < 16; ++i) {
    ASSERT_EQ(in->Read(&edge, Duration::Zero()), ReadStatus::kOk);
    EXPECT_EQ(edge.stamp, kT0 + Duration::Microseconds(i));  // the oldest were kept
    EXPECT_EQ(edge.rising, i % 2 == 0);
    EXPECT_EQ(edge.line, 4U);
  }
  EXPECT_EQ(in->Read(&edge, Duration::Zero()), ReadStatus::kTimeout);
}

TEST(FakeGpioChipTest, FiltersEdgeKindsAfterActiveLowInversion) {
  FakeGpioChip chip;
  auto in = chip.RequestEdges({6, "test", true}, GpioEdges::kRising);
  EXPECT_FALSE(chip.InjectEdge(6, kT0, true));  // physical rise = becoming inactive
  EXPECT_TRUE(chip.InjectEdge(6, kT0 + Duration::Milliseconds(1), false));
  GpioEdge edge;
  ASSERT_EQ(in->Read(&edge, Duration::Zero()), ReadStatus::kOk);
  EXPECT_TRUE(edge.rising);
  EXPECT_EQ(edge.stamp, kT0 + Duration::Milliseconds(1));
  EXPECT_FALSE(chip.InjectEdge(7, kT0, true));  // not requested
}

TEST(FakeGpioChipTest, WireCarriesEdgesWithItsDelay) {
  FakeGpioChip chip;
  chip.Connect(1, 2, Duration::Microseconds(30));
  auto out = chip.RequestOutput({1, "out", false}, false);
  auto in = chip.RequestEdges({2, "in", false}, GpioEdges::kBoth);
  out->Set(true);
  out->Set(false);
  const auto t = chip.transitions(1);
  ASSERT_EQ(t.size(), 2U);
  GpioEdge edge;
  ASSERT_EQ(in->Read(&edge, Duration::Zero()), ReadStatus::kOk);
  EXPECT_TRUE(edge.rising);
  EXPECT_EQ(edge.stamp, t[0].stamp + Duration::Microseconds(30));
  ASSERT_EQ(in->Read(&edge, Duration::Zero()), ReadStatus::kOk);
  EXPECT_FALSE(edge.rising);
  EXPECT_EQ(edge.stamp, t[1].stamp + Duration::Microseconds(30));
}

TEST(FakeGpioChipTest, ReadWaitsForItsTimeout) {
  FakeGpioChip chip;
  auto in = chip.RequestEdges({2, "in", false}, GpioEdges::kBoth);
  GpioEdge edge;
  const Time start = Time::Now();
  EXPECT_EQ(in->Read(&edge, Duration::Milliseconds(5)), ReadStatus::kTimeout);
  EXPECT_GE(Time::Now() - start, Duration::Milliseconds(5));
}

TEST(FakeGpioChipTest, InjectedFailures) {
  FakeGpioChip chip;
  auto out = chip.RequestOutput({1, "out", false}, false);
  auto in = chip.RequestEdges({2, "in", false}, GpioEdges::kBoth);
  chip.FailNextSets(1, 1);
  chip.FailNextReads(2, 1);
  EXPECT_FALSE(out->Set(true));
  EXPECT_FALSE(chip.physical_level(1));
  EXPECT_TRUE(out->Set(true));
  GpioEdge edge;
  EXPECT_EQ(in->Read(&edge, Duration::Zero()), ReadStatus::kError);
  EXPECT_EQ(in->Read(&edge, Duration::Zero()), ReadStatus::kTimeout);
}

TEST(FakeGpioChipTest, RequestErrorsNameChipLineAndHolder) {
  FakeGpioChip chip("bench-chip", 8);
  auto held = chip.RequestOutput({3, "camera", false}, false);
  try {
    chip.RequestEdges({3, "imu", false}, GpioEdges::kRising);
    FAIL() << "expected GpioError";
  } catch (const GpioError& e) {
    EXPECT_THAT(e.what(), HasSubstr("bench-chip line 3"));
    EXPECT_THAT(e.what(), HasSubstr("held by 'camera'"));
    EXPECT_THAT(e.what(), HasSubstr("busy"));
  }
  try {
    chip.RequestOutput({8, "x", false}, false);
    FAIL() << "expected GpioError";
  } catch (const GpioError& e) {
    EXPECT_THAT(e.what(), HasSubstr("bench-chip line 8"));
    EXPECT_THAT(e.what(), HasSubstr("below 8"));
  }
  held.reset();  // released: requestable again
  EXPECT_NO_THROW(chip.RequestEdges({3, "imu", false}, GpioEdges::kRising));
}

}  // namespace
}  // namespace rover::drivers
