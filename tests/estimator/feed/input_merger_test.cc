// The filter's one input order and the bounded merger that produces it on
// the IMU thread: equal stamps, late inputs, a full merger, no allocation,
// and agreement with a global sort (what offline producers use).

#include "estimator/feed/input_merger.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <variant>
#include <vector>

#include "estimator/feed/input_order.h"
#include "tests/support/malloc_counter.h"

namespace rover::estimator {
namespace {

Time Ms(int64_t ms) { return Time::FromNanoseconds(ms * 1'000'000); }

ImuMeasurement Imu(int64_t ms) { return ImuMeasurement{Ms(ms), {}, {}}; }

// A relative pose delivered at `stamp` (its content does not matter here).
RelativePoseMeasurement Pose(Time stamp) {
  RelativePoseMeasurement m;
  m.stamp = stamp;
  m.from_stamp = stamp;
  m.to_stamp = stamp;
  return m;
}

// A short text per input kind, to compare sequences readably.
char KindOf(const EskfInput& input) {
  static constexpr char kKinds[] = "IWTRSP";
  return kKinds[InputRank(input)];
}

std::string Kinds(const std::vector<EskfInput>& inputs) {
  std::string s;
  for (const EskfInput& in : inputs) s += KindOf(in);
  return s;
}

TEST(InputOrderTest, EqualStampsGoImuWheelTriggerRelativePoseRequests) {
  std::vector<EskfInput> in = {
      PoseReportRequest{Ms(5), 1}, FrameSwitchRequest{Ms(5)},        Pose(Ms(5)),
      CloneTrigger{Ms(5)},         WheelSpeedMeasurement{Ms(5), {}}, Imu(5),
      CloneTrigger{Ms(4)}};
  SortInputs(&in);
  EXPECT_EQ(Kinds(in), "TIWTRSP");
  EXPECT_EQ(StampOf(in.front()), Ms(4));
}

TEST(InputOrderTest, SortIsStableWithinAKindAndStamp) {
  std::vector<EskfInput> in = {PoseReportRequest{Ms(3), 7}, PoseReportRequest{Ms(3), 2},
                               PoseReportRequest{Ms(3), 9}};
  SortInputs(&in);
  ASSERT_EQ(in.size(), 3u);
  EXPECT_EQ(std::get<PoseReportRequest>(in[0]).id, 7u);
  EXPECT_EQ(std::get<PoseReportRequest>(in[1]).id, 2u);
  EXPECT_EQ(std::get<PoseReportRequest>(in[2]).id, 9u);
}

TEST(InputMergerTest, FeedsEarlierInputsThenTheSampleThenInputsAtItsStamp) {
  InputMerger<8> merger;
  std::vector<EskfInput> fed;
  const auto feed = [&](const EskfInput& in) { fed.push_back(in); };
  ASSERT_TRUE(merger.Push(CloneTrigger{Ms(10)}));
  ASSERT_TRUE(merger.Push(WheelSpeedMeasurement{Ms(9), {}}));
  ASSERT_TRUE(merger.Push(WheelSpeedMeasurement{Ms(10), {}}));
  ASSERT_TRUE(merger.Push(CloneTrigger{Ms(11)}));
  merger.Step(Imu(10), feed);
  EXPECT_EQ(Kinds(fed), "WIWT");  // 9 ms wheel, the 10 ms sample, then its stamp's inputs
  EXPECT_EQ(merger.size(), 1u);   // the 11 ms trigger waits
  fed.clear();
  merger.Step(Imu(15), feed);
  EXPECT_EQ(Kinds(fed), "TI");
  EXPECT_EQ(merger.late_inputs(), 0u);
}

TEST(InputMergerTest, LateInputsAreFedBeforeTheNextSampleAndCounted) {
  InputMerger<8> merger;
  std::vector<EskfInput> fed;
  const auto feed = [&](const EskfInput& in) { fed.push_back(in); };
  merger.Step(Imu(10), feed);
  ASSERT_TRUE(merger.Push(Pose(Ms(7))));           // before 10 ms: late
  ASSERT_TRUE(merger.Push(CloneTrigger{Ms(10)}));  // at the last sample's stamp: not late
  fed.clear();
  merger.Step(Imu(15), feed);
  EXPECT_EQ(Kinds(fed), "RTI");
  EXPECT_EQ(merger.late_inputs(), 1u);
}

TEST(InputMergerTest, RefusesInputsWhenFullAndTakesThemAfterAStep) {
  InputMerger<3> merger;
  int fed = 0;
  const auto feed = [&](const EskfInput&) { ++fed; };
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(merger.Push(CloneTrigger{Ms(1 + i)}));
  EXPECT_FALSE(merger.Push(CloneTrigger{Ms(4)}));
  EXPECT_EQ(merger.size(), 3u);
  merger.Step(Imu(2), feed);  // two triggers and the sample
  EXPECT_EQ(fed, 3);
  EXPECT_TRUE(merger.Push(CloneTrigger{Ms(4)}));
  fed = 0;
  merger.Drain(feed);
  EXPECT_EQ(fed, 2);
  EXPECT_EQ(merger.size(), 0u);
}

TEST(InputMergerTest, StepAndDrainDoNotAllocate) {
  InputMerger<64> merger;
  uint64_t fed = 0;
  const auto feed = [&](const EskfInput&) { ++fed; };
  const testing::ScopedMallocCheck check;
  for (int64_t t = 0; t < 1000; ++t) {
    if (t % 5 == 0) merger.Push(CloneTrigger{Ms(t)});
    if (t % 2 == 0) merger.Push(WheelSpeedMeasurement{Ms(t + 1), {}});
    merger.Step(Imu(t), feed);
  }
  merger.Drain(feed);
  EXPECT_EQ(check.mallocs(), 0u);
  EXPECT_EQ(fed, 1000u + 200u + 500u);
}

// Inputs handed over in any order before their stamp's IMU sample come out
// exactly as the global sort puts them: roverd, the simulator's feed and
// rover-eval vio compute the same sequence.
TEST(InputMergerTest, AgreesWithTheGlobalSortOnRandomStreams) {
  std::mt19937_64 rng(42);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<EskfInput> aiding;
    for (int i = 0; i < 300; ++i) {
      const Time t = Ms(static_cast<int64_t>(rng() % 500));  // many equal stamps
      switch (rng() % 5) {
        case 0:
          aiding.emplace_back(WheelSpeedMeasurement{t, {}});
          break;
        case 1:
          aiding.emplace_back(CloneTrigger{t});
          break;
        case 2:
          aiding.emplace_back(Pose(t));
          break;
        case 3:
          aiding.emplace_back(FrameSwitchRequest{t});
          break;
        default:
          aiding.emplace_back(PoseReportRequest{t, rng() % 100});
          break;
      }
    }
    std::vector<EskfInput> all = aiding;
    for (int64_t ms = 0; ms < 500; ms += 5) all.emplace_back(Imu(ms));
    SortInputs(&all);

    // Hand each aiding input over at a random point before its stamp's sample.
    std::shuffle(aiding.begin(), aiding.end(), rng);
    const auto sample_index = [](const EskfInput& in) {  // of the first sample at or after it
      return (StampOf(in).nanoseconds() + 4'999'999) / 5'000'000;
    };
    std::stable_sort(aiding.begin(), aiding.end(), [&](const EskfInput& a, const EskfInput& b) {
      return sample_index(a) < sample_index(b);
    });
    InputMerger<512> merger;
    std::vector<EskfInput> fed;
    const auto feed = [&](const EskfInput& in) { fed.push_back(in); };
    std::size_t next = 0;
    for (int64_t ms = 0; ms < 500; ms += 5) {
      while (next < aiding.size() && StampOf(aiding[next]) <= Ms(ms)) {
        ASSERT_TRUE(merger.Push(aiding[next++]));
      }
      merger.Step(Imu(ms), feed);
    }
    while (next < aiding.size()) ASSERT_TRUE(merger.Push(aiding[next++]));
    merger.Drain(feed);
    ASSERT_EQ(fed.size(), all.size());
    for (std::size_t i = 0; i < fed.size(); ++i) {
      ASSERT_EQ(StampOf(fed[i]), StampOf(all[i])) << "trial " << trial << " index " << i;
      ASSERT_EQ(InputRank(fed[i]), InputRank(all[i])) << "trial " << trial << " index " << i;
    }
    EXPECT_EQ(merger.late_inputs(), 0u);
  }
}

}  // namespace
}  // namespace rover::estimator
