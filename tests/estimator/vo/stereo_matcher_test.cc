#include "estimator/vo/stereo_matcher.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>

#include "estimator/vo/feature_detector.h"
#include "tests/estimator/vo/vo_test_util.h"

namespace rover::estimator::vo {
namespace {

constexpr RectifiedIntrinsics kIntrinsics{400.0, 400.0, 320.0, 240.0};
constexpr double kBaseline = 0.12;

// A fronto-parallel textured plane: the right image is the left one shifted
// left by `disparity` pixels.
cv::Mat ShiftLeft(const cv::Mat& image, double disparity) {
  const cv::Mat m = (cv::Mat_<double>(2, 3) << 1.0, 0.0, -disparity, 0.0, 1.0, 0.0);
  cv::Mat out;
  cv::warpAffine(image, out, m, image.size(), cv::INTER_CUBIC, cv::BORDER_REFLECT);
  return out;
}

TEST(StereoMatcherTest, TriangulatesAPlane) {
  const cv::Mat left = testing::RandomTexture(640, 480, 7, 2.0);
  const double disparity = 12.3;
  const cv::Mat right = ShiftLeft(left, disparity);
  // Away from the right edge, where the shifted image is only a reflection.
  std::vector<cv::Point2f> features;
  for (const auto& f : FeatureDetector().Detect(left)) {
    if (f.x < 600.0f) features.push_back(f);
  }
  ASSERT_GT(features.size(), 100u);
  const StereoMatcher matcher(kIntrinsics, kBaseline);
  StereoMatchStats stats;
  const auto points = matcher.Match(left, right, features, &stats);
  EXPECT_GT(points.size(), features.size() * 8 / 10);
  EXPECT_EQ(stats.accepted, static_cast<int>(points.size()));
  const double z = kIntrinsics.fx * kBaseline / disparity;
  for (const auto& p : points) {
    EXPECT_NEAR(p.p_cam0rect.z(), z, 0.02 * z);
    const double zm = p.p_cam0rect.z();
    EXPECT_NEAR(p.depth_sigma_m, zm * zm / (kIntrinsics.fx * kBaseline) * 0.5, 1e-12);
    const cv::Point2f& l = features[static_cast<size_t>(p.feature_index)];
    EXPECT_EQ(p.left, l);
    EXPECT_NEAR(p.p_cam0rect.x() / p.p_cam0rect.z() * kIntrinsics.fx + kIntrinsics.cx, l.x, 1e-6);
  }
}

TEST(StereoMatcherTest, DropsPointsWithLargeDepthUncertainty) {
  const cv::Mat left = testing::RandomTexture(640, 480, 8, 2.0);
  const cv::Mat right = ShiftLeft(left, 2.0);  // z = 24 m, sigma_z = 6 m
  const auto features = FeatureDetector().Detect(left);
  const StereoMatcher matcher(kIntrinsics, kBaseline);
  StereoMatchStats stats;
  EXPECT_TRUE(matcher.Match(left, right, features, &stats).empty());
  EXPECT_GT(stats.depth_sigma_rejected, 0);
}

TEST(StereoMatcherTest, BadInputGivesNoPoints) {
  const StereoMatcher matcher(kIntrinsics, kBaseline);
  const cv::Mat black = cv::Mat::zeros(480, 640, CV_8UC1);
  const std::vector<cv::Point2f> pts = {{100.0f, 100.0f}, {300.0f, 200.0f}};
  EXPECT_TRUE(matcher.Match(cv::Mat(), black, pts).empty());
  EXPECT_TRUE(matcher.Match(black, cv::Mat(), pts).empty());
  EXPECT_TRUE(matcher.Match(black, cv::Mat::zeros(240, 320, CV_8UC1), pts).empty());
  EXPECT_TRUE(matcher.Match(black, black, pts).empty());  // zero disparity on a flat image
  EXPECT_TRUE(matcher.Match(black, black, {}).empty());
}

}  // namespace
}  // namespace rover::estimator::vo
