#include "hil/sim/motion/route.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <stdexcept>

#include "core/config/config.h"

namespace rover::sim {
namespace {

using ::testing::HasSubstr;

TEST(RouteTest, ValidateRejectsSpeedsOutsideLimits) {
  Route route;
  route.DriveTo({5, 0}, 0.6);
  EXPECT_THROW(route.Validate(), std::invalid_argument);
  route.waypoints[0].speed_m_s = 0.05;
  EXPECT_THROW(route.Validate(), std::invalid_argument);
  route.waypoints[0].speed_m_s = 0.1;
  EXPECT_NO_THROW(route.Validate());
  EXPECT_THROW(Route().Validate(), std::invalid_argument);  // no waypoints
}

TEST(RouteTest, RevisitRepeatsAnEarlierPosition) {
  Route route;
  route.start_xy_m = {1, 2};
  route.DriveTo({5, 2}, 0.3).DriveTo({5, 6}, 0.3).Revisit(0, 0.2).Revisit(-1, 0.4, 2.0);
  ASSERT_EQ(route.waypoints.size(), 4u);
  EXPECT_EQ(route.waypoints[2].xy_m, Eigen::Vector2d(5, 2));
  EXPECT_EQ(route.waypoints[3].xy_m, Eigen::Vector2d(1, 2));
  EXPECT_EQ(route.waypoints[3].stop_s, 2.0);
  EXPECT_THROW(route.Revisit(9, 0.3), std::invalid_argument);
}

TEST(RouteTest, LoadsFromYaml) {
  const ConfigNode root = ConfigNode::LoadString(R"(start_xy_m: [0, 0]
start_yaw_rad: 0.5
waypoints:
  - {xy_m: [4, 0], speed_m_s: 0.3}
  - {xy_m: [4, 4], speed_m_s: 0.2, stop_s: 3}
  - {revisit: -1, speed_m_s: 0.5}
)",
                                                 "route.yaml");
  const Route route = Route::Load(root);
  root.CheckNoUnknownKeysRecursive();
  EXPECT_EQ(route.start_yaw_rad, 0.5);
  ASSERT_EQ(route.waypoints.size(), 3u);
  EXPECT_EQ(route.waypoints[1].stop_s, 3.0);
  EXPECT_EQ(route.waypoints[2].xy_m, Eigen::Vector2d(0, 0));
}

TEST(RouteTest, YamlErrorsNameFileLineAndKey) {
  const ConfigNode root = ConfigNode::LoadString(R"(start_xy_m: [0, 0]
start_yaw_rad: 0
waypoints:
  - {xy_m: [4, 0], speed_m_s: 0.9}
)",
                                                 "route.yaml");
  try {
    Route::Load(root);
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_THAT(e.what(), HasSubstr("route.yaml:4"));
    EXPECT_THAT(e.what(), HasSubstr("speed_m_s"));
  }
}

TEST(RouteTest, SurveyLoopClosesOnItsStart) {
  const Route route = MakeSurveyLoopRoute({1, -1}, 8, 6, 2);
  route.Validate();
  EXPECT_EQ(route.waypoints.size(), 10u);
  EXPECT_EQ(route.waypoints[4].xy_m, route.start_xy_m);
  EXPECT_EQ(route.waypoints.back().xy_m, route.start_xy_m);
}

}  // namespace
}  // namespace rover::sim
