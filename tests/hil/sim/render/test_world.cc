#include "tests/hil/sim/render/test_world.h"

#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace rover::sim::testing {

double TestTerrainHeight(const TestWorldOptions& options, double x_m, double y_m) {
  // Wavelengths of metres: gentle slopes (< 15 deg), no self-occlusion from
  // the camera height at the ranges the tests look at.
  return options.amplitude_m *
         (std::sin(2.0 * M_PI * x_m / 7.0) + 0.7 * std::sin(2.0 * M_PI * y_m / 5.0 + 1.0) +
          0.3 * std::sin(2.0 * M_PI * (x_m + y_m) / 3.0));
}

World MakeTestWorld(const TestWorldOptions& options) {
  World world;
  world.seed = options.seed;
  world.options.size_m = options.size_m;
  world.options.resolution_m = options.resolution_m;
  world.options.albedo_resolution_m = options.albedo_resolution_m;
  const int n = static_cast<int>(std::lround(options.size_m / options.resolution_m)) + 1;
  const Eigen::Vector2d origin = Eigen::Vector2d::Constant(-0.5 * options.size_m);
  std::vector<float> heights(static_cast<std::size_t>(n) * static_cast<std::size_t>(n));
  for (int iy = 0; iy < n; ++iy) {
    for (int ix = 0; ix < n; ++ix) {
      heights[static_cast<std::size_t>(iy * n + ix)] = static_cast<float>(TestTerrainHeight(
          options, origin.x() + options.resolution_m * ix, origin.y() + options.resolution_m * iy));
    }
  }
  world.terrain = Heightfield(n, n, options.resolution_m, origin, std::move(heights));

  // Albedo: octaves of seeded noise from the texel scale up to ~2.5 m,
  // upsampled bicubically, so there is texture at every range.
  const int m = static_cast<int>(std::lround(options.size_m / options.albedo_resolution_m)) + 1;
  cv::RNG rng(options.seed);
  cv::Mat sum = cv::Mat::zeros(m, m, CV_32FC1);
  double weight = 1.0;
  for (int cells = m; cells >= 16; cells /= 4) {
    cv::Mat octave(cells, cells, CV_32FC1);
    rng.fill(octave, cv::RNG::UNIFORM, -1.0, 1.0);
    cv::Mat up;
    cv::resize(octave, up, cv::Size(m, m), 0, 0, cv::INTER_CUBIC);
    sum += weight * up;
    weight *= 1.3;
  }
  cv::Mat u8;
  cv::normalize(sum, sum, 40.0, 220.0, cv::NORM_MINMAX);
  sum.convertTo(u8, CV_8U);
  world.albedo.cols = m;
  world.albedo.rows = m;
  world.albedo.resolution_m = options.albedo_resolution_m;
  world.albedo.origin_xy = origin;
  world.albedo.values.assign(u8.datastart, u8.dataend);
  return world;
}

}  // namespace rover::sim::testing
