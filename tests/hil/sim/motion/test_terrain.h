#ifndef ROVER_TESTS_HIL_SIM_MOTION_TEST_TERRAIN_H_
#define ROVER_TESTS_HIL_SIM_MOTION_TEST_TERRAIN_H_

// Heightfields for the motion and sensor tests, built directly through the
// Heightfield constructor (independent of the world generator).

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <functional>
#include <random>
#include <vector>

#include "hil/sim/world/world.h"

namespace rover::sim::testing {

/// Samples `height_m(x, y)` on a square grid of side size_m centred on the
/// origin, plus uniform noise of +-noise_m per cell (seeded).
inline Heightfield MakeHeightfield(double size_m, double resolution_m,
                                   const std::function<double(double, double)>& height_m,
                                   double noise_m = 0.0, uint64_t seed = 1) {
  const int n = static_cast<int>(std::lround(size_m / resolution_m)) + 1;
  const Eigen::Vector2d origin(-0.5 * size_m, -0.5 * size_m);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> noise(-noise_m, noise_m);
  std::vector<float> heights(static_cast<std::size_t>(n) * static_cast<std::size_t>(n));
  for (int iy = 0; iy < n; ++iy) {
    for (int ix = 0; ix < n; ++ix) {
      const double x = origin.x() + ix * resolution_m;
      const double y = origin.y() + iy * resolution_m;
      heights[static_cast<std::size_t>(iy) * static_cast<std::size_t>(n) +
              static_cast<std::size_t>(ix)] =
          static_cast<float>(height_m(x, y) + (noise_m > 0.0 ? noise(rng) : 0.0));
    }
  }
  return Heightfield(n, n, resolution_m, origin, std::move(heights));
}

/// Rolling hills with a short-wave ripple and cell noise: slopes up to about
/// 15 degrees, the kind of ground the strap-down test drives over.
inline Heightfield MakeRoughTerrain(double size_m = 40.0, uint64_t seed = 7) {
  return MakeHeightfield(
      size_m, 0.05,
      [](double x, double y) {
        return 0.2 * std::sin(2.0 * M_PI * x / 8.0) * std::cos(2.0 * M_PI * y / 11.0) +
               0.12 * std::sin(2.0 * M_PI * (0.6 * x + 0.8 * y) / 9.0 + 0.7) +
               0.02 * std::sin(2.0 * M_PI * x / 2.5) * std::sin(2.0 * M_PI * y / 2.1);
      },
      0.003, seed);
}

/// A plane rising along +x at slope_rad.
inline Heightfield MakeInclinedPlane(double slope_rad, double size_m = 40.0) {
  const double gradient = std::tan(slope_rad);
  return MakeHeightfield(size_m, 0.05, [gradient](double x, double) { return gradient * x; });
}

inline Heightfield MakeFlatTerrain(double size_m = 40.0) {
  return MakeHeightfield(size_m, 0.05, [](double, double) { return 0.0; });
}

}  // namespace rover::sim::testing

#endif  // ROVER_TESTS_HIL_SIM_MOTION_TEST_TERRAIN_H_
