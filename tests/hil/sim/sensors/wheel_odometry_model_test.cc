#include "hil/sim/sensors/wheel_odometry_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "drivers/can/canopen_wheel_protocol.h"
#include "tests/hil/sim/motion/test_terrain.h"

namespace rover::sim {
namespace {

const Time kStart = Time::FromNanoseconds(10'000'000'000);

std::string ConfigPath(const std::string& name) {
  const char* source = std::getenv("ROVER_SOURCE_DIR");
  return std::string(source != nullptr ? source : ".") + "/hil/config/" + name;
}

Route StraightRoute(double length_m, double speed_m_s) {
  Route route;
  route.start_xy_m = {-0.5 * length_m, 0.0};
  route.start_hold_s = 1.0;
  route.end_hold_s = 1.0;
  route.DriveTo({0.5 * length_m, 0.0}, speed_m_s);
  return route;
}

std::vector<drivers::CanFrame> RunAll(WheelOdometryModel& model, const RoverTrajectory& tr,
                                      std::vector<WheelSyncState>* states = nullptr) {
  std::vector<drivers::CanFrame> frames;
  model.Advance(kStart + Duration::FromSeconds(tr.duration_s()), &frames, states);
  return frames;
}

TEST(WheelOdometryModelTest, OptionsLoadFromShippedYaml) {
  const WheelOdometryModelOptions o =
      WheelOdometryModelOptions::LoadFile(ConfigPath("wheels.yaml"));
  EXPECT_EQ(o.encoder_counts_per_motor_rev, 4096u);
  EXPECT_EQ(o.ticks_per_wheel_rev(), 409600.0);
  EXPECT_EQ(o.heartbeat_phase_s, Eigen::Vector4d(0.11, 0.37, 0.62, 0.88));
}

// SYNC every 10 ms, then TPDO1 of nodes 1..4 a few hundred microseconds
// later, heartbeats at 1 Hz per node; all in time order, however Advance is
// sliced.
TEST(WheelOdometryModelTest, FrameIdsAndTiming) {
  const Heightfield terrain = testing::MakeRoughTerrain();
  const RoverTrajectory tr(StraightRoute(4.0, 0.3), terrain);
  const WheelOdometryModelOptions o =
      WheelOdometryModelOptions::LoadFile(ConfigPath("wheels.yaml"));
  WheelOdometryModel model(o, tr, terrain, kStart);
  std::vector<drivers::CanFrame> frames;
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<int> slice_us(1, 30000);
  Time until = kStart;
  while (until < kStart + Duration::Seconds(3)) {
    until = std::min(until + Duration::Microseconds(slice_us(rng)), kStart + Duration::Seconds(3));
    model.Advance(until, &frames);
  }
  WheelOdometryModel one_shot(o, tr, terrain, kStart);
  std::vector<drivers::CanFrame> reference;
  one_shot.Advance(kStart + Duration::Seconds(3), &reference);
  ASSERT_EQ(frames.size(), reference.size());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    ASSERT_EQ(frames[i].stamp, reference[i].stamp);
    ASSERT_EQ(frames[i].id, reference[i].id);
    ASSERT_EQ(frames[i].data, reference[i].data);
  }

  std::vector<Time> syncs;
  std::vector<std::vector<Time>> beats(4);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const drivers::CanFrame& f = frames[i];
    ASSERT_LT(f.stamp, kStart + Duration::Seconds(3));
    if (i > 0) {
      ASSERT_GE(f.stamp, frames[i - 1].stamp);
    }
    if (drivers::IsSync(f)) {
      syncs.push_back(f.stamp);
      // The next four wheel frames are TPDO1 of nodes 1..4, in order.
      int node = 1;
      for (std::size_t j = i + 1; j < frames.size() && node <= 4; ++j) {
        if (drivers::DecodeHeartbeat(frames[j])) continue;
        const auto tpdo = drivers::DecodeWheelTpdo1(frames[j]);
        ASSERT_TRUE(tpdo.has_value()) << "frame " << j;
        EXPECT_EQ(tpdo->node_id, node);
        const double delay_us = (frames[j].stamp - f.stamp).ToMicroseconds();
        EXPECT_GE(delay_us, 150.0);
        EXPECT_LE(delay_us, 700.0);
        ++node;
      }
      EXPECT_EQ(node, 5);
    } else if (const auto beat = drivers::DecodeHeartbeat(f)) {
      ASSERT_GE(beat->node_id, 1);
      ASSERT_LE(beat->node_id, 4);
      EXPECT_EQ(beat->nmt_state, drivers::kNmtOperational);
      beats[beat->node_id - 1u].push_back(f.stamp);
    } else {
      ASSERT_TRUE(drivers::DecodeWheelTpdo1(f).has_value());
    }
  }
  ASSERT_EQ(syncs.size(), 300u);
  for (std::size_t k = 0; k < syncs.size(); ++k) {
    EXPECT_EQ(syncs[k], kStart + Duration::Milliseconds(10) * static_cast<int64_t>(k));
  }
  EXPECT_EQ(frames.size(), 300u * 5u + 12u);
  for (int node = 0; node < 4; ++node) {
    ASSERT_EQ(beats[static_cast<std::size_t>(node)].size(), 3u);
    for (int n = 0; n < 3; ++n) {
      EXPECT_EQ(beats[static_cast<std::size_t>(node)][static_cast<std::size_t>(n)],
                kStart + Duration::FromSeconds(o.heartbeat_phase_s[node]) + Duration::Seconds(n));
    }
  }
}

// Flat ground, no slip: the encoders count exactly the wheel rotation of the
// distance driven, and report the rolling rate.
TEST(WheelOdometryModelTest, TicksMatchWheelRotationWithoutSlip) {
  const Heightfield flat = testing::MakeFlatTerrain();
  const RoverTrajectory tr(StraightRoute(6.0, 0.3), flat);
  WheelOdometryModelOptions o;  // ideal: no slip, no noise, no scrub
  WheelOdometryModel model(o, tr, flat, kStart);
  std::vector<WheelSyncState> states;
  const std::vector<drivers::CanFrame> frames = RunAll(model, tr, &states);
  const double r = tr.options().wheel_radius_m;
  const double x0 = tr.Evaluate(0.0).p_world_body.x();
  for (const WheelSyncState& s : states) {
    const TrajectorySample truth = tr.Evaluate((s.stamp - kStart).ToSeconds());
    const double angle = (truth.p_world_body.x() - x0) / r;
    for (int w = 0; w < kWheelCount; ++w) {
      const auto i = static_cast<std::size_t>(w);
      // Trapezoid error h^2 / 12 * (change of angular acceleration): ~1e-7
      // rad, far below one tick (1.5e-5 rad).
      EXPECT_NEAR(s.angle_rad[i], angle, 1e-6);
      EXPECT_NEAR(s.angular_velocity_rad_s[i], truth.v_world_m_s.x() / r, 1e-12);
      EXPECT_EQ(s.slip_ratio[i], 0.0);
    }
  }
  const double ticks_per_rad = o.ticks_per_wheel_rev() / (2.0 * M_PI);
  const auto expected_ticks = static_cast<int32_t>(std::floor(6.0 / r * ticks_per_rad));
  std::array<int32_t, 4> last_position{};
  int32_t max_velocity = 0;
  for (const drivers::CanFrame& f : frames) {
    if (const auto tpdo = drivers::DecodeWheelTpdo1(f)) {
      last_position[tpdo->node_id - 1u] = tpdo->position_ticks;
      max_velocity = std::max(max_velocity, tpdo->velocity_mrad_s);
    }
  }
  for (int32_t p : last_position) EXPECT_NEAR(p, expected_ticks, 1);
  EXPECT_EQ(max_velocity, 3000);  // 0.3 m/s on a 0.1 m wheel
}

TEST(WheelOdometryModelTest, TurnOnTheSpotCountsLeftBackRightForward) {
  const Heightfield flat = testing::MakeFlatTerrain();
  Route route;
  route.start_yaw_rad = 0.0;
  route.DriveTo({0.0, 3.0}, 0.3);  // a 90 deg left turn on the spot first
  const RoverTrajectory tr(route, flat);
  double turn_end = 0.0;
  for (const PhaseInterval& p : tr.phases()) {
    if (p.phase == MotionPhase::kTurnInPlace) turn_end = p.end_s;
  }
  WheelOdometryModelOptions o;
  o.yaw_scrub_factor = 1.3;
  WheelOdometryModel model(o, tr, flat, kStart);
  std::vector<WheelSyncState> states;
  std::vector<drivers::CanFrame> frames;
  model.Advance(kStart + Duration::FromSeconds(turn_end), &frames, &states);
  const WheelSyncState& s = states.back();
  // Each wheel travels the arc yaw * half track, scaled by the scrub factor.
  const double arc_rad = 1.3 * 0.5 * M_PI * 0.25 / 0.1;
  EXPECT_NEAR(s.angle_rad[kFrontLeft], -arc_rad, 1e-4);
  EXPECT_NEAR(s.angle_rad[kRearLeft], -arc_rad, 1e-4);
  EXPECT_NEAR(s.angle_rad[kFrontRight], arc_rad, 1e-4);
  EXPECT_NEAR(s.angle_rad[kRearRight], arc_rad, 1e-4);
  EXPECT_LT(s.encoder_ticks[kFrontLeft], 0);
  EXPECT_GT(s.encoder_ticks[kFrontRight], 0);
}

double MeanCruiseSlip(const Heightfield& terrain, const WheelOdometryModelOptions& o) {
  const RoverTrajectory tr(StraightRoute(6.0, 0.3), terrain);
  WheelOdometryModel model(o, tr, terrain, kStart);
  std::vector<WheelSyncState> states;
  RunAll(model, tr, &states);
  double sum = 0.0;
  int n = 0;
  for (const WheelSyncState& s : states) {
    if (tr.PhaseAt((s.stamp - kStart).ToSeconds()) != MotionPhase::kCruise) continue;
    for (double slip : s.slip_ratio) sum += slip;
    n += 4;
  }
  return sum / n;
}

TEST(WheelOdometryModelTest, SlipGrowsOnSlopesAndRoughGround) {
  WheelOdometryModelOptions o = WheelOdometryModelOptions::LoadFile(ConfigPath("wheels.yaml"));
  const double flat = MeanCruiseSlip(testing::MakeFlatTerrain(), o);
  const double slope = MeanCruiseSlip(testing::MakeInclinedPlane(12.0 * M_PI / 180.0), o);
  const double rough = MeanCruiseSlip(testing::MakeHeightfield(
                                          40.0, 0.05, [](double, double) { return 0.0; }, 0.02, 3),
                                      o);
  EXPECT_NEAR(flat, o.slip_base_ratio, 0.01);
  EXPECT_NEAR(slope - flat, o.slip_slope_gain_per_rad * 12.0 * M_PI / 180.0, 0.01);
  EXPECT_GT(rough - flat, 0.02);

  // With slip the encoders count more than the distance driven.
  const Heightfield plane = testing::MakeInclinedPlane(12.0 * M_PI / 180.0);
  const RoverTrajectory tr(StraightRoute(6.0, 0.3), plane);
  WheelOdometryModel model(o, tr, plane, kStart);
  std::vector<WheelSyncState> states;
  RunAll(model, tr, &states);
  const double ground_m = 6.0 / std::cos(12.0 * M_PI / 180.0);
  EXPECT_GT(states.back().angle_rad[0] * 0.1, ground_m * 1.1);
}

TEST(WheelOdometryModelTest, SameSeedSameFrames) {
  const Heightfield terrain = testing::MakeRoughTerrain();
  const RoverTrajectory tr(StraightRoute(3.0, 0.3), terrain);
  WheelOdometryModelOptions o = WheelOdometryModelOptions::LoadFile(ConfigPath("wheels.yaml"));
  WheelOdometryModel a(o, tr, terrain, kStart), b(o, tr, terrain, kStart);
  o.seed += 1;
  WheelOdometryModel c(o, tr, terrain, kStart);
  const std::vector<drivers::CanFrame> fa = RunAll(a, tr), fb = RunAll(b, tr), fc = RunAll(c, tr);
  ASSERT_EQ(fa.size(), fb.size());
  bool differs = false;
  for (std::size_t i = 0; i < fa.size(); ++i) {
    ASSERT_EQ(fa[i].stamp, fb[i].stamp);
    ASSERT_EQ(fa[i].data, fb[i].data);
    differs |= i < fc.size() && fa[i].data != fc[i].data;
  }
  EXPECT_TRUE(differs);
}

}  // namespace
}  // namespace rover::sim
