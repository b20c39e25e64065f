#include "estimator/vo/feature_detector.h"

#include <gtest/gtest.h>

#include <vector>

#include "tests/estimator/vo/vo_test_util.h"

namespace rover::estimator::vo {
namespace {

TEST(FeatureDetectorTest, SpreadsFeaturesOverTheGrid) {
  const cv::Mat image = testing::RandomTexture(640, 480, 1);
  FeatureDetectorOptions options;
  options.cell_size_px = 40;
  options.max_per_cell = 2;
  const FeatureDetector detector(options);
  const std::vector<cv::Point2f> features = detector.Detect(image);
  const int cells = (640 / 40) * (480 / 40);
  // Every cell away from the border gets its quota; none exceeds it.
  EXPECT_GT(static_cast<int>(features.size()), cells * 3 / 2);
  std::vector<int> count(static_cast<size_t>(cells), 0);
  for (const auto& p : features) {
    EXPECT_GE(p.x, 12.0f);
    EXPECT_GE(p.y, 12.0f);
    EXPECT_LT(p.x, 628.0f);
    EXPECT_LT(p.y, 468.0f);
    ++count[static_cast<size_t>(static_cast<int>(p.y) / 40 * 16 + static_cast<int>(p.x) / 40)];
  }
  for (int c : count) EXPECT_LE(c, 2);
}

TEST(FeatureDetectorTest, IsDeterministic) {
  const cv::Mat image = testing::RandomTexture(320, 240, 2);
  const FeatureDetector detector;
  EXPECT_EQ(detector.Detect(image), detector.Detect(image));
}

TEST(FeatureDetectorTest, KeepsAwayFromExistingFeatures) {
  const cv::Mat image = testing::RandomTexture(320, 240, 3);
  FeatureDetectorOptions options;
  options.max_per_cell = 5;
  const FeatureDetector detector(options);
  const std::vector<cv::Point2f> first = detector.Detect(image);
  ASSERT_FALSE(first.empty());
  const std::vector<cv::Point2f> second = detector.Detect(image, first);
  for (const auto& p : second) {
    for (const auto& q : first) {
      const cv::Point2f d = p - q;
      EXPECT_GE(d.dot(d), 63.9f);
    }
  }
  // Cells are already full: a repeated detection adds nothing.
  const std::vector<cv::Point2f> all = [&] {
    std::vector<cv::Point2f> v = first;
    v.insert(v.end(), second.begin(), second.end());
    return v;
  }();
  EXPECT_TRUE(detector.Detect(image, all).size() <= second.size());
}

TEST(FeatureDetectorTest, BadImagesGiveNoFeatures) {
  const FeatureDetector detector;
  EXPECT_TRUE(detector.Detect(cv::Mat()).empty());
  EXPECT_TRUE(detector.Detect(cv::Mat::zeros(480, 640, CV_8UC1)).empty());
  EXPECT_TRUE(detector.Detect(cv::Mat(480, 640, CV_8UC1, cv::Scalar(255))).empty());
  EXPECT_TRUE(detector.Detect(cv::Mat::zeros(480, 640, CV_32FC1)).empty());
  EXPECT_TRUE(detector.Detect(cv::Mat::zeros(4, 4, CV_8UC1)).empty());
}

}  // namespace
}  // namespace rover::estimator::vo
