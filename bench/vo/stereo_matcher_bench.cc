// Runtime of StereoMatcher::Match on real rectified EuRoC V1_01 pairs
// (752 x 480, ~300 FAST features), one core: ms per call (median of repeated
// calls) and accepted points for
//   - the exhaustive reference (the matcher before it became coarse-to-fine:
//     cv::matchTemplate over the whole disparity range and row band, both
//     directions), measured in the same run since the shared machines drift,
//   - Match() with the full disparity search,
//   - Match() with a disparity prior per feature: the full search's disparity
//     plus a seeded error of up to +-2 px (half the default radius; the
//     hovering excerpt would make frame-to-frame priors almost exact), and no
//     prior (full search) for features the full search did not match, as for
//     newly detected features.
// "same" counts points that the other run also accepted with the right pixel
// within 0.01 px. Target: full search <= 5 ms for 300 features with
// the reference's accepted count +-5 %.
//
// usage: bench_stereo_matcher [EUROC_DIR]   (default: the shared excerpt)

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "core/calib/euroc_sensor_yaml.h"
#include "core/calib/stereo_rectifier.h"
#include "drivers/replay/euroc_dataset.h"
#include "estimator/vo/feature_detector.h"
#include "estimator/vo/stereo_matcher.h"
#include "tests/estimator/vo/euroc_vo_util.h"
#include "tests/estimator/vo/stereo_matcher_reference.h"

namespace rover::estimator::vo {
namespace {

constexpr int kCalls = 21;
constexpr size_t kFrames[] = {0, 50, 80};

double MedianMs(const std::function<void()>& fn) {
  std::vector<double> ms;
  for (int i = 0; i < kCalls; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    fn();
    const auto t1 = std::chrono::steady_clock::now();
    ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
  }
  std::nth_element(ms.begin(), ms.begin() + kCalls / 2, ms.end());
  return ms[kCalls / 2];
}

// Points of `a` that `b` accepted too, with the right pixel within 0.01 px.
int Same(const std::vector<StereoPoint>& a, const std::vector<StereoPoint>& b) {
  int same = 0;
  for (const auto& p : a) {
    for (const auto& q : b) {
      if (p.feature_index == q.feature_index) {
        const cv::Point2f e = p.right - q.right;
        same += std::hypot(e.x, e.y) <= 0.01f ? 1 : 0;
        break;
      }
    }
  }
  return same;
}

int Run(const std::string& dir) {
  const auto cam0 = calib::LoadEurocCamera(dir + "/mav0/cam0/sensor.yaml");
  const auto cam1 = calib::LoadEurocCamera(dir + "/mav0/cam1/sensor.yaml");
  const auto rectifier = calib::StereoRectifier::Create(cam0, cam1);
  if (!rectifier.has_value()) {
    std::fprintf(stderr, "unusable calibration in %s\n", dir.c_str());
    return 1;
  }
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(dir + "/mav0/cam0/data")) {
    if (std::filesystem::exists(dir + "/mav0/cam1/data/" + e.path().filename().string())) {
      names.push_back(e.path().filename().string());
    }
  }
  std::sort(names.begin(), names.end());

  const StereoMatcher matcher(rectifier->intrinsics(), rectifier->baseline_m());
  std::printf("Stereo matching, EuRoC %dx%d, median of %d calls [ms per call, accepted points]\n",
              cam0.width_px, cam0.height_px, kCalls);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> prior_error(-2.0f, 2.0f);
  for (const size_t frame : kFrames) {
    if (frame >= names.size()) continue;
    const cv::Mat raw0 = cv::imread(dir + "/mav0/cam0/data/" + names[frame], cv::IMREAD_GRAYSCALE);
    const cv::Mat raw1 = cv::imread(dir + "/mav0/cam1/data/" + names[frame], cv::IMREAD_GRAYSCALE);
    cv::Mat left, right;
    if (!rectifier->Rectify(raw0, raw1, &left, &right)) {
      std::fprintf(stderr, "cannot read frame %zu\n", frame);
      return 1;
    }
    const auto features = FeatureDetector().Detect(left);

    std::vector<StereoPoint> reference, full, prior;
    const double reference_ms = MedianMs(
        [&] { reference = testing::ReferenceStereoMatch(matcher, left, right, features); });
    const double full_ms = MedianMs([&] { full = matcher.Match(left, right, features); });
    std::vector<float> disparity(features.size(), -1.0f);
    for (const auto& p : full) {
      disparity[static_cast<size_t>(p.feature_index)] = p.left.x - p.right.x + prior_error(rng);
    }
    StereoMatchStats stats;
    const double prior_ms =
        MedianMs([&] { prior = matcher.Match(left, right, features, &stats, &disparity); });

    std::printf("frame %2zu, %zu features:\n", frame, features.size());
    std::printf("  reference (exhaustive)  %6.2f ms  %3zu points\n", reference_ms,
                reference.size());
    std::printf(
        "  full search             %6.2f ms  %3zu points  (%d same as reference)  "
        "x%.1f faster\n",
        full_ms, full.size(), Same(full, reference), reference_ms / full_ms);
    std::printf(
        "  with prior (%3d known)  %6.2f ms  %3zu points  (%d same as full search)  "
        "x%.1f faster\n",
        stats.prior_searches, prior_ms, prior.size(), Same(prior, full), reference_ms / prior_ms);
  }
  return 0;
}

}  // namespace
}  // namespace rover::estimator::vo

int main(int argc, char** argv) {
  const char* shared = std::getenv("ROVER_SHARED_DIR");
  const std::string dir = argc > 1            ? argv[1]
                          : shared != nullptr ? std::string(shared) + "/data/euroc_v1_01_micro"
                                              : std::string(ROVER_STEREO_BENCH_DATA);
  try {
    return rover::estimator::vo::Run(dir);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
}
