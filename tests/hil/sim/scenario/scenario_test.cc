#include "hil/sim/scenario/scenario.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "hil/sim/motion/rover_trajectory.h"
#include "tests/support/temp_dir.h"

namespace rover::sim {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

Heightfield Flat() {
  return Heightfield(401, 401, 0.5, Eigen::Vector2d(-100, -100), std::vector<float>(401 * 401));
}

Scenario Load(const std::string& name) {
  return LoadScenario(FindScenario(DefaultScenarioDir(), name), DefaultSimConfigDir());
}

TEST(ScenarioTest, TheShippedScenariosLoad) {
  std::vector<std::string> names;
  for (const std::string& f : ListScenarioFiles(DefaultScenarioDir())) {
    const Scenario s = LoadScenario(f, DefaultSimConfigDir());
    EXPECT_EQ(s.name, fs::path(f).stem().string()) << "name must match the file name";
    names.push_back(s.name);
  }
  EXPECT_THAT(names,
              ::testing::IsSupersetOf({"short", "loop-100m", "mixed-300m", "two-rovers",
                                       "figure-eight-1km", "monotonous-200m", "landmarks-200m"}));
}

TEST(ScenarioTest, RouteLengthsAndDurationsMatchTheirNames) {
  const Heightfield flat = Flat();
  const RoverTrajectory short_run(Load("short").route, flat);
  EXPECT_NEAR(short_run.duration_s(), 60.0, 6.0);
  const RoverTrajectory loop(Load("loop-100m").route, flat);
  EXPECT_NEAR(loop.distance_m(), 100.0, 5.0);
  const RoverTrajectory mixed(Load("mixed-300m").route, flat);
  EXPECT_NEAR(mixed.distance_m(), 300.0, 15.0);
  const RoverTrajectory eight(Load("figure-eight-1km").route, flat);
  EXPECT_NEAR(eight.distance_m(), 1000.0, 30.0);
  const RoverTrajectory lanes(Load("monotonous-200m").route, flat);
  EXPECT_NEAR(lanes.distance_m(), 200.0, 10.0);
}

TEST(ScenarioTest, TheLandmarkLoopSeesItsPostsAgainAfterAHundredMetres) {
  const Scenario s = Load("landmarks-200m");
  ASSERT_EQ(s.world.landmark_posts_xy_m.size(), 4u);
  EXPECT_EQ(s.world.landmark_post_count, 4);
  const RoverTrajectory lanes(s.route, Flat());
  // Each post stands beside the route, never on it, and at least one is
  // passed again (within 6 m, ahead) after 100 m or more of driving.
  double longest_gap_m = 0.0;
  for (const Eigen::Vector2d& post : s.world.landmark_posts_xy_m) {
    double nearest_m = 1e9;
    double first_m = -1.0;
    double last_m = -1.0;
    double driven_m = 0.0;
    Eigen::Vector2d previous = lanes.Evaluate(0.0).p_world_body.head<2>();
    for (double t = 0.0; t <= lanes.duration_s(); t += 0.5) {
      const TrajectorySample x = lanes.Evaluate(t);
      const Eigen::Vector2d p = x.p_world_body.head<2>();
      driven_m += (p - previous).norm();
      previous = p;
      const Eigen::Vector2d to_post = post - p;
      nearest_m = std::min(nearest_m, to_post.norm());
      const Eigen::Vector2d forward = (x.q_world_body * Eigen::Vector3d::UnitX()).head<2>();
      if (to_post.norm() < 6.0 && to_post.dot(forward) > 0.0) {
        if (first_m < 0.0) first_m = driven_m;
        last_m = driven_m;
      }
    }
    EXPECT_GT(nearest_m, 1.5) << "post at " << post.transpose() << " on the route";
    EXPECT_LT(nearest_m, 3.0) << "post at " << post.transpose() << " out of sight";
    longest_gap_m = std::max(longest_gap_m, last_m - first_m);
  }
  EXPECT_GE(longest_gap_m, 100.0);
}

TEST(ScenarioTest, TheFigureEightRevisitsItsGroundFromTheOppositeDirection) {
  const Heightfield flat = Flat();
  const RoverTrajectory eight(Load("figure-eight-1km").route, flat);
  // Halfway, the rover passes the crossing again and retraces the first
  // half backwards: at mirrored times it is at the same place, heading the
  // other way.
  const double half_s = 0.5 * eight.duration_s();
  int checked = 0;
  for (double f = 0.05; f < 0.45; f += 0.05) {
    const double t_s = f * eight.duration_s();
    const TrajectorySample a = eight.Evaluate(t_s);
    const TrajectorySample b = eight.Evaluate(2.0 * half_s - t_s);
    if ((a.p_world_body - b.p_world_body).head<2>().norm() > 3.0) continue;
    const Eigen::Vector3d forward_a = a.q_world_body * Eigen::Vector3d::UnitX();
    const Eigen::Vector3d forward_b = b.q_world_body * Eigen::Vector3d::UnitX();
    EXPECT_LT(forward_a.dot(forward_b), -0.9) << "at t = " << t_s << " s";
    ++checked;
  }
  EXPECT_GE(checked, 3) << "the reverse pass must retrace the forward one";
}

TEST(ScenarioTest, MixedRunsAlongTheCraterWithoutEnteringIt) {
  const Scenario s = Load("mixed-300m");
  ASSERT_EQ(s.world.crater_centers_xy_m.size(), 1u);
  const double d = DistanceToClearPaths(s.world, s.world.crater_centers_xy_m[0]);
  // The first crater's radius is 5-7 m: the route passes 1-6 m outside its rim.
  EXPECT_GT(d, 7.0 + 1.0);
  EXPECT_LT(d, 5.0 + 6.0);
}

TEST(ScenarioTest, TwoRoversHaveOneMovingCarrierAndCrossingRoutes) {
  const Scenario s = Load("two-rovers");
  EXPECT_EQ(s.world.other_rover_count, 1);
  ASSERT_EQ(s.other_rover_routes.size(), 1u);
  EXPECT_EQ(s.world.clear_paths_xy_m.size(), 2u);
}

TEST(ScenarioTest, UnknownNameListsKnownOnes) {
  try {
    FindScenario(DefaultScenarioDir(), "moon-landing");
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("moon-landing"));
    EXPECT_THAT(e.what(), HasSubstr("loop-100m"));
  }
}

TEST(ScenarioTest, UnknownKeyIsAnErrorWithFileAndLine) {
  const testing::TempDir dir("scenario");
  const std::string path = dir.File("bad.yaml").string();
  std::ofstream(path)
      << "name: bad\ndescription: x\nroute:\n  start_xy_m: [0, 0]\n  start_yaw_rad: 0\n"
         "  waypoints:\n    - {xy_m: [5, 0], speed_m_s: 0.3}\n"
         "sensors:\n  imu_config: imu_mti10.yaml\n  camera_rate: 10\n";
  try {
    LoadScenario(path, DefaultSimConfigDir());
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_THAT(e.what(), HasSubstr("bad.yaml:10"));
    EXPECT_THAT(e.what(), HasSubstr("camera_rate"));
  }
}

TEST(ScenarioTest, ARouteLeavingTheWorldIsRefusedWithTheWaypoint) {
  const testing::TempDir dir("scenario");
  const std::string path = dir.File("off_the_edge.yaml").string();
  std::ofstream(path) << "name: off_the_edge\ndescription: x\nworld: {size_m: 90}\nroute:\n"
                         "  start_xy_m: [0, 0]\n  start_yaw_rad: 0\n"
                         "  waypoints:\n    - {xy_m: [30, 0], speed_m_s: 0.3}\n    - {xy_m: [52, "
                         "0], speed_m_s: 0.3}\n"
                         "sensors:\n  imu_config: imu_mti10.yaml\n";
  try {
    LoadScenario(path, DefaultSimConfigDir());
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_THAT(e.what(), HasSubstr("waypoint 1 at (52, 0) m is outside the 90 m world"));
    EXPECT_THAT(e.what(), HasSubstr("<= 40 m"));
  }
}

}  // namespace
}  // namespace rover::sim
