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

TEST(ScenarioTest, TheFourShippedScenariosLoad) {
  std::vector<std::string> names;
  for (const std::string& f : ListScenarioFiles(DefaultScenarioDir())) {
    const Scenario s = LoadScenario(f, DefaultSimConfigDir());
    EXPECT_EQ(s.name, fs::path(f).stem().string()) << "name must match the file name";
    names.push_back(s.name);
  }
  EXPECT_THAT(names, ::testing::IsSupersetOf({"short", "loop-100m", "mixed-300m", "two-rovers"}));
}

TEST(ScenarioTest, RouteLengthsAndDurationsMatchTheirNames) {
  const Heightfield flat = Flat();
  const RoverTrajectory short_run(Load("short").route, flat);
  EXPECT_NEAR(short_run.duration_s(), 60.0, 6.0);
  const RoverTrajectory loop(Load("loop-100m").route, flat);
  EXPECT_NEAR(loop.distance_m(), 100.0, 5.0);
  const RoverTrajectory mixed(Load("mixed-300m").route, flat);
  EXPECT_NEAR(mixed.distance_m(), 300.0, 15.0);
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

}  // namespace
}  // namespace rover::sim
