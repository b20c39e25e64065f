// The rovers of a team scenario: which route each drives, their names, which
// moving tag carrier is whose, and the per-rover IMU seed that datasets and
// live missions share.

#include "hil/sim/scenario/team_rovers.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <stdexcept>

namespace rover::sim {
namespace {

using ::testing::HasSubstr;

Scenario Load(const std::string& name) {
  return LoadScenario(FindScenario(DefaultScenarioDir(), name), DefaultSimConfigDir());
}

Eigen::Vector2d StartXy(const RoverTrajectory& t) { return t.Evaluate(0.0).p_world_body.head<2>(); }

// The message of the std::invalid_argument that `f` throws ("" if none).
template <typename F>
std::string InvalidArgumentMessage(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(TeamRoversTest, TwoRoversDriveTheirOwnRoutesAndHideTheirOwnCarrier) {
  const Scenario s = Load("two-rovers");
  const World world = World::Generate(s.world, 1);
  const TeamRovers team = MakeTeamRovers(s, world);
  ASSERT_EQ(team.size(), 2u);
  EXPECT_EQ(team.names, (std::vector<std::string>{"rover_a", "rover_b"}));
  // Rover 0 drives `route` from (0, 0), rover 1 other_rovers[0] from (14, 0).
  EXPECT_LT((StartXy(team.trajectories[0]) - Eigen::Vector2d(0.0, 0.0)).norm(), 1e-6);
  EXPECT_LT((StartXy(team.trajectories[1]) - Eigen::Vector2d(14.0, 0.0)).norm(), 1e-6);
  EXPECT_NEAR(team.trajectories[0].duration_s(),
              RoverTrajectory(s.route, world.terrain).duration_s(), 1e-9);
  EXPECT_NEAR(team.trajectories[1].duration_s(),
              RoverTrajectory(s.other_rover_routes[0], world.terrain).duration_s(), 1e-9);
  // World order of the moving carriers: rover_b, then rover_a.
  EXPECT_EQ(team.carrier_rover, (std::vector<std::size_t>{1, 0}));
  const std::vector<const RoverTrajectory*> carriers = team.CarrierTrajectories();
  ASSERT_EQ(carriers.size(), 2u);
  EXPECT_EQ(carriers[0], &team.trajectories[1]);
  EXPECT_EQ(carriers[1], &team.trajectories[0]);
  // Each rover's camera hides its own body and shows the other's.
  EXPECT_EQ(team.HiddenCarrier(0), 1u);
  EXPECT_EQ(team.HiddenCarrier(1), 0u);
}

TEST(TeamRoversTest, ASingleRoverIsRoverAWithoutCarriers) {
  const Scenario s = Load("short");
  const World world = World::Generate(s.world, 1);
  const TeamRovers team = MakeTeamRovers(s, world);
  ASSERT_EQ(team.size(), 1u);
  EXPECT_EQ(team.names, (std::vector<std::string>{"rover_a"}));
  EXPECT_TRUE(team.carrier_rover.empty());
  EXPECT_TRUE(team.CarrierTrajectories().empty());
  EXPECT_EQ(team.HiddenCarrier(0), kNoHiddenCarrier);
}

TEST(TeamRoversTest, AMovingCarrierWithoutARouteIsRefusedByName) {
  const Scenario s = Load("two-rovers");
  World world = World::Generate(s.world, 1);
  TagCarrier extra;
  extra.name = "rover_c";
  extra.is_static = false;
  world.carriers.insert(world.carriers.end() - 1, extra);  // before rover_a, as the world orders
  EXPECT_THAT(InvalidArgumentMessage([&] { MakeTeamRovers(s, world); }), HasSubstr("rover_c"));
}

TEST(TeamRoversTest, ARoverIndexOutsideTheTeamIsRefusedNamingTheCount) {
  const Scenario two = Load("two-rovers");
  EXPECT_EQ(RoverCount(two), 2u);
  EXPECT_NO_THROW(CheckRoverIndex(two, 0));
  EXPECT_NO_THROW(CheckRoverIndex(two, 1));
  const std::string message = InvalidArgumentMessage([&] { CheckRoverIndex(two, 2); });
  EXPECT_THAT(message, HasSubstr("rover 2"));
  EXPECT_THAT(message, HasSubstr("two-rovers"));
  EXPECT_THAT(message, HasSubstr("has 2 rovers"));

  const Scenario one = Load("short");
  EXPECT_EQ(RoverCount(one), 1u);
  EXPECT_NO_THROW(CheckRoverIndex(one, 0));
  EXPECT_THAT(InvalidArgumentMessage([&] { CheckRoverIndex(one, 1); }), HasSubstr("has 1 rover"));
}

// Pinned: changing the formula would change every generated dataset.
TEST(TeamRoversTest, ImuSeedsArePerRoverAndPinned) {
  Scenario s;
  s.imu.seed = 7;
  EXPECT_EQ(RoverImuSeed(s, 3, 0), 0xdaa66d2c7ddf7438ULL);
  EXPECT_EQ(RoverImuSeed(s, 3, 1), 0x1814c3115a0b9f77ULL);
  EXPECT_EQ(RoverImuSeed(s, 3, 2), 0x5fc331563276a2a6ULL);
}

}  // namespace
}  // namespace rover::sim
