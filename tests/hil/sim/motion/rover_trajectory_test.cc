#include "hil/sim/motion/rover_trajectory.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include "core/config/config.h"
#include "core/geometry/so3.h"
#include "tests/hil/sim/motion/test_terrain.h"

namespace rover::sim {
namespace {

constexpr double kDeg = M_PI / 180.0;

// Turns on the spot, a rounded corner, speed changes between legs, a stop,
// and a loop back to the start.
Route TestRoute() {
  Route route;
  route.start_xy_m = {-3.0, -2.0};
  route.start_yaw_rad = 0.3;
  route.start_hold_s = 1.0;
  route.end_hold_s = 1.0;
  route
      .DriveTo({1.0, -1.7}, 0.4)      // turn on the spot first (17 deg -> 4 deg)
      .DriveTo({4.0, -2.2}, 0.25)     // gentle corner at (1, -1.7), -14 deg: rounded off
      .DriveTo({4.0, 1.0}, 0.3, 2.0)  // corner of 100 deg at (4, -2.2): turn on the spot
      .DriveTo({1.5, 1.5}, 0.5)       // 2 s stop at (4, 1), then turn on the spot
      .Revisit(-1, 0.2);              // 49 deg turn at (1.5, 1.5), back to the start
  return route;
}

class RoverTrajectoryTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    terrain_ = new Heightfield(testing::MakeRoughTerrain());
    trajectory_ = new RoverTrajectory(TestRoute(), *terrain_);
  }
  static void TearDownTestSuite() {
    delete trajectory_;
    delete terrain_;
  }
  static Heightfield* terrain_;
  static RoverTrajectory* trajectory_;
};
Heightfield* RoverTrajectoryTest::terrain_ = nullptr;
RoverTrajectory* RoverTrajectoryTest::trajectory_ = nullptr;

double HorizontalSpeed(const TrajectorySample& s) { return s.v_world_m_s.head<2>().norm(); }

// Rates, acceleration, angular acceleration and specific force must be the
// exact derivatives of the pose: compare with central differences.
TEST_F(RoverTrajectoryTest, RatesMatchNumericDerivatives) {
  const RoverTrajectory& tr = *trajectory_;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> when(0.01, tr.duration_s() - 0.01);
  const double h = 1e-4;
  for (int i = 0; i < 400; ++i) {
    const double t = when(rng);
    const TrajectorySample now = tr.Evaluate(t), before = tr.Evaluate(t - h),
                           after = tr.Evaluate(t + h);
    const Eigen::Vector3d v_numeric = (after.p_world_body - before.p_world_body) / (2 * h);
    EXPECT_LT((v_numeric - now.v_world_m_s).norm(), 1e-6) << "t=" << t;
    const Eigen::Vector3d a_numeric = (after.v_world_m_s - before.v_world_m_s) / (2 * h);
    EXPECT_LT((a_numeric - now.a_world_m_s2).norm(), 1e-4) << "t=" << t;
    const Eigen::Vector3d omega_numeric =
        LogSO3(before.q_world_body.conjugate() * after.q_world_body) / (2 * h);
    EXPECT_LT((omega_numeric - now.omega_body_rad_s).norm(), 1e-6) << "t=" << t;
    const Eigen::Vector3d alpha_numeric =
        (after.omega_body_rad_s - before.omega_body_rad_s) / (2 * h);
    EXPECT_LT((alpha_numeric - now.alpha_body_rad_s2).norm(), 1e-4) << "t=" << t;
    const Eigen::Vector3d f =
        now.q_world_body.conjugate() * (now.a_world_m_s2 + Eigen::Vector3d(0, 0, 9.80665));
    EXPECT_LT((f - now.specific_force_body_m_s2).norm(), 1e-12) << "t=" << t;
  }
}

// C^2: velocity, acceleration and angular rate do not jump where one analytic
// piece (hold, turn, ramp, cruise, straight, corner) meets the next.
TEST_F(RoverTrajectoryTest, ContinuousAcrossEveryKnot) {
  const RoverTrajectory& tr = *trajectory_;
  const std::vector<double> knots = tr.KnotTimes_s();
  ASSERT_GT(knots.size(), 20u);
  const double e = 1e-7;
  for (double t : knots) {
    if (t <= e || t >= tr.duration_s() - e) continue;
    const TrajectorySample a = tr.Evaluate(t - e), b = tr.Evaluate(t + e);
    EXPECT_LT((a.p_world_body - b.p_world_body).norm(), 1e-6) << "t=" << t;
    EXPECT_LT((a.v_world_m_s - b.v_world_m_s).norm(), 1e-5) << "t=" << t;
    EXPECT_LT((a.a_world_m_s2 - b.a_world_m_s2).norm(), 1e-4) << "t=" << t;
    EXPECT_LT((a.omega_body_rad_s - b.omega_body_rad_s).norm(), 1e-5) << "t=" << t;
    EXPECT_LT((a.alpha_body_rad_s2 - b.alpha_body_rad_s2).norm(), 1e-3) << "t=" << t;
    // The same through finite differences taken on each side of the knot.
    const double h = 1e-4;
    const Eigen::Vector3d v_left =
        (tr.Evaluate(t).p_world_body - tr.Evaluate(t - h).p_world_body) / h;
    const Eigen::Vector3d v_right =
        (tr.Evaluate(t + h).p_world_body - tr.Evaluate(t).p_world_body) / h;
    EXPECT_LT((v_left - v_right).norm(), 1e-3) << "t=" << t;
  }
}

TEST_F(RoverTrajectoryTest, RespectsSpeedLimitsStopsAndTurnsOnTheSpot) {
  const RoverTrajectory& tr = *trajectory_;
  int turns = 0, holds = 0, cruises = 0;
  for (const PhaseInterval& phase : tr.phases()) {
    ASSERT_LT(phase.begin_s, phase.end_s);
    turns += phase.phase == MotionPhase::kTurnInPlace;
    holds += phase.phase == MotionPhase::kHold;
    cruises += phase.phase == MotionPhase::kCruise;
    const TrajectorySample first = tr.Evaluate(phase.begin_s);
    for (double t = phase.begin_s; t <= phase.end_s; t += 0.01) {
      const TrajectorySample s = tr.Evaluate(t);
      switch (phase.phase) {
        case MotionPhase::kHold:
          EXPECT_EQ(s.v_world_m_s, Eigen::Vector3d::Zero()) << "t=" << t;
          EXPECT_EQ(s.a_world_m_s2, Eigen::Vector3d::Zero()) << "t=" << t;
          EXPECT_EQ(s.omega_body_rad_s, Eigen::Vector3d::Zero()) << "t=" << t;
          EXPECT_EQ(s.p_world_body, first.p_world_body) << "t=" << t;
          break;
        case MotionPhase::kTurnInPlace:
          // x, y stay put (z follows the terrain under the turning wheels).
          EXPECT_EQ(s.v_world_m_s.head<2>(), Eigen::Vector2d::Zero()) << "t=" << t;
          EXPECT_EQ(s.p_world_body.head<2>(), first.p_world_body.head<2>()) << "t=" << t;
          break;
        case MotionPhase::kCruise:
          EXPECT_GE(phase.speed_m_s, kMinLegSpeed_m_s);
          EXPECT_LE(phase.speed_m_s, kMaxLegSpeed_m_s);
          EXPECT_NEAR(HorizontalSpeed(s), phase.speed_m_s, 1e-12) << "t=" << t;
          break;
        case MotionPhase::kAccelerate:
        case MotionPhase::kDecelerate:
          EXPECT_LE(HorizontalSpeed(s), kMaxLegSpeed_m_s + 1e-12) << "t=" << t;
          EXPECT_LE(s.a_world_m_s2.head<2>().dot(s.v_world_m_s.head<2>().normalized()),
                    tr.options().max_accel_m_s2 + 1e-9);
          break;
      }
    }
  }
  EXPECT_EQ(turns, 4);  // start, corner at (4, -2.2), after the stop, at (1.5, 1.5)
  EXPECT_GE(holds, 3);  // start, the 2 s stop, end
  EXPECT_GE(cruises, 5);
  for (double t = 0.0; t < tr.duration_s(); t += 0.01) {
    EXPECT_LE(HorizontalSpeed(tr.Evaluate(t)), kMaxLegSpeed_m_s + 1e-12);
    EXPECT_LE(std::abs(tr.Evaluate(t).omega_body_rad_s.z()), 1.0);
  }
}

TEST_F(RoverTrajectoryTest, GentleCornerIsRoundedWhileDriving) {
  const RoverTrajectory& tr = *trajectory_;
  // Near the gentle corner at (1, -1.7) the rover keeps moving and yaws.
  double min_distance = 1e9, speed_there = 0.0, yaw_rate_there = 0.0;
  for (double t = 0.0; t < tr.duration_s(); t += 0.005) {
    const TrajectorySample s = tr.Evaluate(t);
    const double d = (s.p_world_body.head<2>() - Eigen::Vector2d(1.0, -1.7)).norm();
    if (d < min_distance) {
      min_distance = d;
      speed_there = HorizontalSpeed(s);
      yaw_rate_there = s.omega_body_rad_s.z();
    }
  }
  EXPECT_LT(min_distance, 0.2);
  EXPECT_GT(min_distance, 1e-3);  // the corner is cut, not driven through
  EXPECT_GE(speed_there, 0.25 - 1e-9);
  EXPECT_LT(yaw_rate_there, -0.05);  // turning right
}

TEST_F(RoverTrajectoryTest, LoopEndsWhereItStarted) {
  const RoverTrajectory& tr = *trajectory_;
  const TrajectorySample start = tr.Evaluate(0.0), end = tr.Evaluate(tr.duration_s());
  EXPECT_LT((start.p_world_body.head<2>() - end.p_world_body.head<2>()).norm(), 1e-9);
  EXPECT_EQ(tr.Evaluate(-5.0).p_world_body, start.p_world_body);  // clamped
  EXPECT_NEAR(tr.distance_m(), 18.5, 0.1);
  EXPECT_GT(tr.duration_s(), 60.0);
}

TEST(RoverTrajectoryTerrainTest, PoseFollowsAnInclinedPlane) {
  const double slope = 10.0 * kDeg;
  const Heightfield plane = testing::MakeInclinedPlane(slope);
  Route uphill;
  uphill.start_xy_m = {-5, 0};
  uphill.DriveTo({5, 0}, 0.3).DriveTo({5, 5}, 0.3);
  const RoverTrajectory tr(uphill, plane);
  const RoverTrajectoryOptions& o = tr.options();
  // On a plane the rim touches it r (1 / cos - 1) above the axle's foot.
  const double lift = o.wheel_radius_m * (1.0 / std::cos(slope) - 1.0);
  const TrajectorySample s = tr.Evaluate(12.0);
  ASSERT_NEAR(s.p_world_body.y(), 0.0, 1e-12);
  EXPECT_NEAR(s.p_world_body.z(), std::tan(slope) * s.p_world_body.x() + lift + o.body_height_m,
              2e-3);
  const Eigen::Matrix3d R = s.q_world_body.toRotationMatrix();
  EXPECT_NEAR(std::asin(-R(2, 0)), -slope, 1e-6);        // pitch: nose up is negative
  EXPECT_NEAR(std::atan2(R(2, 1), R(2, 2)), 0.0, 1e-6);  // roll
  // Driving along +y on the same plane: the left side (-x) is lower.
  const TrajectorySample side = tr.Evaluate(tr.duration_s() - 3.0);
  const Eigen::Matrix3d Rs = side.q_world_body.toRotationMatrix();
  EXPECT_NEAR(std::atan2(Rs(2, 1), Rs(2, 2)), -slope, 1e-6);
  EXPECT_NEAR(std::asin(-Rs(2, 0)), 0.0, 1e-6);
  // Climbing at constant speed: the accelerometer sees only the reaction to
  // gravity, tilted into the body frame by the slope.
  const double t_cruise = 12.0;
  ASSERT_EQ(tr.PhaseAt(t_cruise), MotionPhase::kCruise);
  EXPECT_LT((tr.Evaluate(t_cruise).specific_force_body_m_s2 -
             Eigen::Vector3d(9.80665 * std::sin(slope), 0.0, 9.80665 * std::cos(slope)))
                .norm(),
            1e-6);
}

TEST(RoverTrajectoryTerrainTest, WheelRollingSpeeds) {
  const Heightfield flat = testing::MakeFlatTerrain();
  Route route;
  route.DriveTo({6, 0}, 0.4).DriveTo({6, 4}, 0.4);
  const RoverTrajectory tr(route, flat);
  double t_cruise = -1.0, t_turn = -1.0;
  for (const PhaseInterval& p : tr.phases()) {
    if (p.phase == MotionPhase::kCruise && t_cruise < 0) t_cruise = 0.5 * (p.begin_s + p.end_s);
    if (p.phase == MotionPhase::kTurnInPlace) t_turn = 0.5 * (p.begin_s + p.end_s);
  }
  ASSERT_GT(t_cruise, 0.0);
  ASSERT_GT(t_turn, 0.0);
  for (double v : tr.WheelRollingSpeeds_m_s(tr.Evaluate(t_cruise))) EXPECT_NEAR(v, 0.4, 1e-12);
  // A left turn on the spot: left wheels roll backwards, right wheels forwards,
  // each at yaw rate * half track (scaled by the scrub factor).
  const TrajectorySample s = tr.Evaluate(t_turn);
  const double w = s.omega_body_rad_s.z();
  ASSERT_GT(w, 0.1);
  const auto speeds = tr.WheelRollingSpeeds_m_s(s, 1.3);
  EXPECT_NEAR(speeds[kFrontLeft], -1.3 * w * 0.25, 1e-12);
  EXPECT_NEAR(speeds[kRearLeft], -1.3 * w * 0.25, 1e-12);
  EXPECT_NEAR(speeds[kFrontRight], 1.3 * w * 0.25, 1e-12);
  EXPECT_NEAR(speeds[kRearRight], 1.3 * w * 0.25, 1e-12);
  EXPECT_NEAR(tr.distance_m(), 10.0, 1e-9);
}

TEST(RoverTrajectoryTerrainTest, RejectsLegsTooShortForTheirSpeedChanges) {
  const Heightfield flat = testing::MakeFlatTerrain();
  Route route;
  route.DriveTo({0.3, 0}, 0.5);
  EXPECT_THROW(RoverTrajectory(route, flat), std::invalid_argument);
}

TEST(RoverTrajectoryTerrainTest, OptionsLoadFromShippedYaml) {
  const char* source = std::getenv("ROVER_SOURCE_DIR");
  ASSERT_NE(source, nullptr);
  const ConfigNode root =
      ConfigNode::LoadFile(std::string(source) + "/hil/config/rover_motion.yaml");
  const RoverTrajectoryOptions o = RoverTrajectoryOptions::Load(root);
  root.CheckNoUnknownKeysRecursive();
  EXPECT_EQ(o.wheelbase_m, 0.6);
  EXPECT_EQ(o.track_m, 0.5);
  EXPECT_EQ(o.wheel_radius_m, 0.1);
}

}  // namespace
}  // namespace rover::sim
