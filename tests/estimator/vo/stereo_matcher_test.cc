#include "estimator/vo/stereo_matcher.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <limits>
#include <vector>

#include "estimator/vo/feature_detector.h"
#include "tests/estimator/vo/stereo_matcher_reference.h"
#include "tests/estimator/vo/vo_test_util.h"

namespace rover::estimator::vo {
namespace {

constexpr calib::RectifiedIntrinsics kIntrinsics{400.0, 400.0, 320.0, 240.0};
constexpr double kBaseline = 0.12;

// A fronto-parallel textured plane: the right image is the left one shifted
// left by `disparity` pixels (and down by `row_shift`, a rectification error).
cv::Mat ShiftLeft(const cv::Mat& image, double disparity, double row_shift = 0.0) {
  const cv::Mat m = (cv::Mat_<double>(2, 3) << 1.0, 0.0, -disparity, 0.0, 1.0, row_shift);
  cv::Mat out;
  cv::warpAffine(image, out, m, image.size(), cv::INTER_CUBIC, cv::BORDER_REFLECT);
  return out;
}

// Features away from the right edge, where the shifted image is only a reflection.
std::vector<cv::Point2f> PlaneFeatures(const cv::Mat& left) {
  std::vector<cv::Point2f> features;
  for (const auto& f : FeatureDetector().Detect(left)) {
    if (f.x < 600.0f) features.push_back(f);
  }
  return features;
}

// Both accepted the same features at the same right pixels.
void ExpectSamePoints(const std::vector<StereoPoint>& a, const std::vector<StereoPoint>& b,
                      float tolerance_px) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].feature_index, b[i].feature_index);
    EXPECT_NEAR(a[i].right.x, b[i].right.x, tolerance_px) << "feature " << a[i].feature_index;
    EXPECT_NEAR(a[i].right.y, b[i].right.y, tolerance_px) << "feature " << a[i].feature_index;
  }
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

// The coarse-to-fine search finds what the exhaustive one finds (cv::matchTemplate
// over every row of the band at every disparity), also when the match is off
// the feature's row.
TEST(StereoMatcherTest, MatchesTheExhaustiveSearch) {
  const StereoMatcher matcher(kIntrinsics, kBaseline);
  for (const double row_shift : {0.0, 0.4, -0.7}) {
    SCOPED_TRACE(row_shift);
    const cv::Mat left = testing::RandomTexture(640, 480, 11, 2.0);
    const cv::Mat right = ShiftLeft(left, 23.6, row_shift);
    const auto features = PlaneFeatures(left);
    StereoMatchStats stats, reference_stats;
    const auto points = matcher.Match(left, right, features, &stats);
    const auto reference =
        testing::ReferenceStereoMatch(matcher, left, right, features, &reference_stats);
    EXPECT_GT(points.size(), features.size() * 8 / 10);
    // matchTemplate's float sums differ from the exact ones by ~1e-4 in NCC.
    ExpectSamePoints(points, reference, 1e-3f);
    // (A spurious weak peak may be missed, which only moves a rejection from
    // the consistency check to the search.)
    EXPECT_EQ(stats.search_rejected + stats.consistency_rejected,
              reference_stats.search_rejected + reference_stats.consistency_rejected);
    // The parabola's sub-pixel error on this texture (the same as the reference's).
    double disparity_error = 0.0, row_error = 0.0;
    for (const auto& p : points) {
      disparity_error += std::abs(static_cast<double>(p.left.x - p.right.x) - 23.6);
      row_error += std::abs(static_cast<double>(p.right.y - p.left.y) - row_shift);
    }
    EXPECT_LT(disparity_error / static_cast<double>(points.size()), 0.15);
    EXPECT_LT(row_error / static_cast<double>(points.size()), 0.15);
  }
}

TEST(StereoMatcherTest, PriorNearTheTruthFindsTheSameMatches) {
  const cv::Mat left = testing::RandomTexture(640, 480, 12, 2.0);
  const cv::Mat right = ShiftLeft(left, 31.3, 0.3);
  const auto features = PlaneFeatures(left);
  const StereoMatcher matcher(kIntrinsics, kBaseline);
  const auto full = matcher.Match(left, right, features);
  ASSERT_GT(full.size(), features.size() * 8 / 10);
  // Priors off by up to 3 px (inside the default 4 px radius), both ways.
  std::vector<float> prior(features.size());
  for (size_t i = 0; i < prior.size(); ++i) {
    prior[i] = 31.3f + 3.0f * std::sin(static_cast<float>(i));
  }
  StereoMatchStats stats;
  const auto restricted = matcher.Match(left, right, features, &stats, &prior);
  EXPECT_EQ(stats.prior_searches, static_cast<int>(features.size()));
  ExpectSamePoints(restricted, full, 0.0f);
  // Also with a tight window around an exact prior.
  const std::vector<float> exact(features.size(), 31.3f);
  ExpectSamePoints(matcher.Match(left, right, features, nullptr, &exact, 1.0), full, 0.0f);
}

TEST(StereoMatcherTest, PriorFarOffFindsNothingWrong) {
  const cv::Mat left = testing::RandomTexture(640, 480, 13, 2.0);
  const cv::Mat right = ShiftLeft(left, 31.3);
  const auto features = PlaneFeatures(left);
  const StereoMatcher matcher(kIntrinsics, kBaseline);
  // No window holds the true disparity: far away, and just beside it on
  // either side (where the correlation still rises at the window's edge).
  // Random texture correlates >= min_ncc by chance inside such windows; the
  // full right -> left check must reject all of those.
  for (const float prior_px : {12.0f, 60.0f, 26.0f, 36.5f}) {
    SCOPED_TRACE(prior_px);
    const std::vector<float> prior(features.size(), prior_px);
    StereoMatchStats stats;
    EXPECT_TRUE(matcher.Match(left, right, features, &stats, &prior, 4.0).empty());
    EXPECT_EQ(stats.prior_searches, static_cast<int>(features.size()));
  }
}

TEST(StereoMatcherTest, UnknownPriorsAreSearchedInFull) {
  const cv::Mat left = testing::RandomTexture(640, 480, 14, 2.0);
  const cv::Mat right = ShiftLeft(left, 17.8);
  const auto features = PlaneFeatures(left);
  const StereoMatcher matcher(kIntrinsics, kBaseline);
  const auto full = matcher.Match(left, right, features);
  std::vector<float> prior(features.size());
  for (size_t i = 0; i < prior.size(); ++i) {
    const float kUnknown[] = {-1.0f, std::numeric_limits<float>::quiet_NaN(),
                              std::numeric_limits<float>::infinity(), 17.8f};
    prior[i] = kUnknown[i % 4];
  }
  StereoMatchStats stats;
  ExpectSamePoints(matcher.Match(left, right, features, &stats, &prior), full, 0.0f);
  EXPECT_EQ(stats.prior_searches, static_cast<int>(features.size() / 4));
  // A prior vector that does not fit the points is bad input.
  prior.pop_back();
  EXPECT_TRUE(matcher.Match(left, right, features, nullptr, &prior).empty());
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
