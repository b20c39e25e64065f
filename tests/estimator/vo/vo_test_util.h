#ifndef ROVER_TESTS_ESTIMATOR_VO_VO_TEST_UTIL_H_
#define ROVER_TESTS_ESTIMATOR_VO_VO_TEST_UTIL_H_

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <cstdint>

namespace rover::estimator::vo::testing {

/// Seeded, blurred random texture with full 8-bit contrast.
inline cv::Mat RandomTexture(int width, int height, uint64_t seed, double blur_sigma = 1.5) {
  cv::RNG rng(seed);
  cv::Mat noise(height, width, CV_8UC1);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  cv::Mat blurred, out;
  cv::GaussianBlur(noise, blurred, cv::Size(0, 0), blur_sigma);
  cv::normalize(blurred, out, 0, 255, cv::NORM_MINMAX);
  return out;
}

}  // namespace rover::estimator::vo::testing

#endif  // ROVER_TESTS_ESTIMATOR_VO_VO_TEST_UTIL_H_
