#ifndef ROVER_TESTS_HIL_SIM_RENDER_TEST_WORLD_H_
#define ROVER_TESTS_HIL_SIM_RENDER_TEST_WORLD_H_

// Small synthetic worlds for the renderer tests, built by filling the World
// structs directly (independent of the world generator): a smooth
// sinusoidal heightfield and a seeded multi-scale albedo texture.

#include <cstdint>

#include "hil/sim/world/world.h"

namespace rover::sim::testing {

struct TestWorldOptions {
  double size_m = 40.0;  ///< square, centred on the origin
  double resolution_m = 0.05;
  double albedo_resolution_m = 0.025;
  double amplitude_m = 0.15;  ///< of the height undulations (0: flat at z = 0)
  uint64_t seed = 7;
};

/// Terrain z = amplitude * (sum of three sinusoids), no carriers.
World MakeTestWorld(const TestWorldOptions& options);

/// The analytic terrain height of MakeTestWorld at (x, y), for reference.
double TestTerrainHeight(const TestWorldOptions& options, double x_m, double y_m);

}  // namespace rover::sim::testing

#endif  // ROVER_TESTS_HIL_SIM_RENDER_TEST_WORLD_H_
