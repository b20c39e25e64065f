#ifndef ROVER_TESTS_HIL_SIM_WORLD_TEST_WORLDS_H_
#define ROVER_TESTS_HIL_SIM_WORLD_TEST_WORLDS_H_

// Worlds shared by the world tests: generated once per test binary, since a
// default-size world takes seconds (more under the sanitizers).

#include <Eigen/Core>

#include "hil/sim/world/world.h"

namespace rover::sim::testing {

/// 40 m x 40 m at 5 cm: fast, yet with a crater, rocks, posts and two other rovers.
inline WorldOptions SmallWorldOptions() {
  WorldOptions options;
  options.size_m = 40.0;
  options.rock_count = 80;
  options.landmark_post_count = 4;
  options.other_rover_count = 2;
  return options;
}

inline const World& SmallWorld() {
  static const World world = World::Generate(SmallWorldOptions(), 42);
  return world;
}

/// True if (x, y) lies on or next to a rock or a crater, where the slope limit does not hold.
inline bool NearRockOrCrater(const World& world, const Eigen::Vector2d& xy, double margin_m) {
  for (const Rock& rock : world.rocks) {
    if ((rock.center_xy - xy).norm() < RockOuterRadius(rock) + margin_m) return true;
  }
  for (const Crater& crater : world.craters) {
    if ((crater.center_xy - xy).norm() < CraterOuterRadius(crater) + margin_m) return true;
  }
  return false;
}

}  // namespace rover::sim::testing

#endif  // ROVER_TESTS_HIL_SIM_WORLD_TEST_WORLDS_H_
