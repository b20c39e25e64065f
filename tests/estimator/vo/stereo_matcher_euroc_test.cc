// StereoMatcher's coarse-to-fine and prior-restricted searches against the
// exhaustive reference on real EuRoC V1_01 frames (ROVER_SHARED_DIR).

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "core/calib/stereo_rectifier.h"
#include "drivers/replay/euroc_dataset.h"
#include "estimator/vo/feature_detector.h"
#include "estimator/vo/stereo_matcher.h"
#include "tests/estimator/vo/euroc_vo_util.h"
#include "tests/estimator/vo/stereo_matcher_reference.h"

namespace rover::estimator::vo {
namespace {

// Points of `a` that `b` accepted too, with the right pixel within `tolerance_px`.
int Same(const std::vector<StereoPoint>& a, const std::vector<StereoPoint>& b, float tolerance_px) {
  int same = 0;
  for (const auto& p : a) {
    for (const auto& q : b) {
      if (p.feature_index == q.feature_index) {
        const cv::Point2f e = p.right - q.right;
        same += std::hypot(e.x, e.y) <= tolerance_px ? 1 : 0;
        break;
      }
    }
  }
  return same;
}

TEST(StereoMatcherEurocTest, AgreesWithTheExhaustiveSearch) {
  const char* shared = std::getenv("ROVER_SHARED_DIR");
  const std::string dir =
      std::string(shared != nullptr ? shared : "../shared") + "/data/euroc_v1_01_micro";
  const auto dataset = drivers::EurocDataset::Load(dir);
  const auto rectifier = calib::StereoRectifier::Create(dataset.cam0(), dataset.cam1());
  ASSERT_TRUE(rectifier.has_value());
  const StereoMatcher matcher(rectifier->intrinsics(), rectifier->baseline_m());
  for (const size_t frame : {0u, 40u, 80u}) {
    SCOPED_TRACE(frame);
    const auto& files = dataset.stereo_frames().at(frame);
    cv::Mat left, right;
    ASSERT_TRUE(rectifier->Rectify(cv::imread(files.cam0_path, cv::IMREAD_GRAYSCALE),
                                   cv::imread(files.cam1_path, cv::IMREAD_GRAYSCALE), &left,
                                   &right));
    const auto features = FeatureDetector().Detect(left);
    const auto reference = testing::ReferenceStereoMatch(matcher, left, right, features);
    const auto full = matcher.Match(left, right, features);
    ASSERT_GT(reference.size(), 200u);
    // The few that differ are edges, where the NCC is a ridge with near-equal
    // maxima along it, and NCCs at the thresholds (matchTemplate's float sums
    // are ~1e-4 off).
    EXPECT_NEAR(static_cast<double>(full.size()), static_cast<double>(reference.size()),
                0.02 * static_cast<double>(reference.size()));
    EXPECT_GE(Same(full, reference, 0.01f), static_cast<int>(reference.size()) * 97 / 100);

    // A disparity prior up to 2 px off gives the full search's matches.
    std::vector<float> prior(features.size(), -1.0f);
    for (const auto& p : full) {
      prior[static_cast<size_t>(p.feature_index)] =
          p.left.x - p.right.x + 2.0f * std::sin(static_cast<float>(p.feature_index));
    }
    const auto restricted = matcher.Match(left, right, features, nullptr, &prior);
    EXPECT_GE(Same(restricted, full, 0.0f), static_cast<int>(full.size()) * 99 / 100);
    EXPECT_LE(restricted.size(), full.size() + full.size() / 100);
  }
}

}  // namespace
}  // namespace rover::estimator::vo
