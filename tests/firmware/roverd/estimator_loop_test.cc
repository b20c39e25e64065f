// roverd's estimator loop: inputs handed over through the rings are merged in
// stamp order, every input and output is logged, a replay of the log is
// bit-exact (and a changed option is caught and named), and the IMU step
// allocates nothing.

#include "firmware/roverd/estimator_loop.h"

#include <gtest/gtest.h>

#include <string>
#include <variant>

#include "core/log/flight/flight_log.h"
#include "estimator/io/log_replay.h"
#include "hil/sim/estimator_feed/filter_feed.h"
#include "hil/sim/estimator_feed/filter_run.h"
#include "hil/sim/scenario/scenario.h"
#include "tests/support/allocation_counter.h"
#include "tests/support/malloc_counter.h"
#include "tests/support/temp_dir.h"

namespace rover::roverd {
namespace {

const sim::FilterFeed& Feed() {
  static const sim::FilterFeed* feed = [] {
    sim::FilterFeedOptions o;
    o.max_duration_s = 30.0;
    o.frame_switch_distance_m = 2.0;  // a few switches, so their records are compared too
    return new sim::FilterFeed(
        sim::LoadScenario(sim::FindScenario(sim::DefaultScenarioDir(), "short"),
                          sim::DefaultSimConfigDir()),
        5, o);
  }();
  return *feed;
}

// Hands the feed's inputs to the loop as roverd's threads would: aiding inputs
// through the rings, IMU samples as Step() calls.
void Run(EstimatorLoop* loop, const sim::FilterFeed& feed) {
  for (const estimator::EskfInput& input : feed.inputs()) {
    std::visit(
        [&](const auto& m) {
          using T = std::decay_t<decltype(m)>;
          if constexpr (std::is_same_v<T, estimator::ImuMeasurement>) {
            loop->Step(m);
          } else if constexpr (std::is_same_v<T, estimator::RelativePoseMeasurement>) {
            ASSERT_TRUE(loop->PushRelativePose(m));
          } else if constexpr (std::is_same_v<T, estimator::WheelSpeedMeasurement>) {
            ASSERT_TRUE(loop->PushWheelSpeeds(m));
          } else if constexpr (std::is_same_v<T, estimator::CloneTrigger>) {
            ASSERT_TRUE(loop->PushCloneTrigger(m));
          } else if constexpr (std::is_same_v<T, estimator::FrameSwitchRequest>) {
            ASSERT_TRUE(loop->PushFrameSwitchRequest(m));
          }
        },
        input);
  }
  loop->Drain();
}

// Records a log of the feed; `logged_options` go into the metadata.
std::string Record(const rover::testing::TempDir& dir, const estimator::EskfOptions& options,
                   const estimator::EskfOptions& logged_options, EstimatorLoopStats* stats) {
  const std::string path = (dir.path() / "mission.mcap").string();
  log::FlightLog flight_log;
  flight_log.Open(path);
  const EstimatorLogChannels channels = EstimatorLogChannels::Add(&flight_log, logged_options);
  flight_log.Start();
  EstimatorLoop loop(options, channels, nullptr, /*lockstep=*/true);
  Run(&loop, Feed());
  flight_log.Stop();
  *stats = loop.stats();
  EXPECT_EQ(flight_log.stats().dropped, 0u);
  EXPECT_TRUE(flight_log.stats().error.empty()) << flight_log.stats().error;
  return path;
}

TEST(EstimatorLoopTest, ReplayOfTheLogIsBitExact) {
  const rover::testing::TempDir dir;
  const estimator::EskfOptions options = sim::EskfOptionsForFeed(Feed());
  EstimatorLoopStats stats;
  const std::string path = Record(dir, options, options, &stats);
  EXPECT_EQ(stats.inputs, Feed().inputs().size());
  EXPECT_EQ(stats.ring_drops, 0u);
  EXPECT_EQ(stats.late_inputs, 0u);

  const estimator::io::ReplayResult r = estimator::io::ReplayLog(path);
  EXPECT_TRUE(r.bit_exact) << r.first_difference;
  EXPECT_EQ(r.inputs, stats.inputs);
  EXPECT_EQ(r.states_compared, stats.states);
  EXPECT_GT(Feed().counts().frame_switches, 1u);
  EXPECT_EQ(r.switches_compared, Feed().counts().frame_switches);
  EXPECT_EQ(r.unlogged_outputs, 0u);
}

TEST(EstimatorLoopTest, ReplayWithOtherOptionsNamesTheFirstDifference) {
  const rover::testing::TempDir dir;
  const estimator::EskfOptions options = sim::EskfOptionsForFeed(Feed());
  estimator::EskfOptions other = options;
  other.imu.gyro_noise_density_rad_s_sqrt_hz *= 1.0 + 1e-9;  // a hair's difference
  EstimatorLoopStats stats;
  const std::string path = Record(dir, options, other, &stats);
  const estimator::io::ReplayResult r = estimator::io::ReplayLog(path);
  EXPECT_FALSE(r.bit_exact);
  EXPECT_NE(r.first_difference.find("differs: covariance["), std::string::npos)
      << r.first_difference;
}

TEST(EstimatorLoopTest, StepAndPushesDoNotAllocate) {
  const estimator::EskfOptions options = sim::EskfOptionsForFeed(Feed());
  log::FlightLog flight_log;
  const rover::testing::TempDir dir;
  flight_log.Open((dir.path() / "a.mcap").string());
  const EstimatorLogChannels channels = EstimatorLogChannels::Add(&flight_log, options);
  flight_log.Start();
  EstimatorLoop loop(options, channels);
  const auto& inputs = Feed().inputs();
  const std::size_t warm_up = inputs.size() / 3;  // initialised, clones and keyframes in use
  std::size_t k = 0;
  const auto hand_over = [&](std::size_t end) {
    for (; k < end; ++k) {
      std::visit(
          [&](const auto& m) {
            using T = std::decay_t<decltype(m)>;
            if constexpr (std::is_same_v<T, estimator::ImuMeasurement>) loop.Step(m);
            if constexpr (std::is_same_v<T, estimator::RelativePoseMeasurement>) {
              loop.PushRelativePose(m);
            }
            if constexpr (std::is_same_v<T, estimator::WheelSpeedMeasurement>) {
              loop.PushWheelSpeeds(m);
            }
            if constexpr (std::is_same_v<T, estimator::CloneTrigger>) loop.PushCloneTrigger(m);
            if constexpr (std::is_same_v<T, estimator::FrameSwitchRequest>) {
              loop.PushFrameSwitchRequest(m);
            }
          },
          inputs[k]);
    }
  };
  hand_over(warm_up);
  ASSERT_TRUE(loop.filter().initialised());
  {
    rover::testing::ScopedAllocationCheck news;
    rover::testing::ScopedMallocCheck mallocs;
    hand_over(2 * warm_up);
    EXPECT_EQ(news.allocations(), 0u);
    EXPECT_EQ(mallocs.mallocs(), 0u);
  }
  flight_log.Stop();
  EXPECT_GT(loop.filter().health().Accepted(estimator::InputKind::kRelativePose), 50u);
}

}  // namespace
}  // namespace rover::roverd
