#include "estimator/vo/temporal_tracker.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "estimator/vo/feature_detector.h"
#include "tests/estimator/vo/vo_test_util.h"

namespace rover::estimator::vo {
namespace {

cv::Mat Shift(const cv::Mat& image, double dx, double dy) {
  const cv::Mat m = (cv::Mat_<double>(2, 3) << 1.0, 0.0, dx, 0.0, 1.0, dy);
  cv::Mat out;
  cv::warpAffine(image, out, m, image.size(), cv::INTER_CUBIC, cv::BORDER_REFLECT);
  return out;
}

TEST(TemporalTrackerTest, FollowsAShiftedImage) {
  const cv::Mat ref = testing::RandomTexture(640, 480, 21, 2.0);
  const cv::Mat cur = Shift(ref, 7.4, -3.2);
  std::vector<cv::Point2f> features;
  for (const auto& f : FeatureDetector().Detect(ref)) {
    if (f.x > 30.0f && f.y > 30.0f && f.x < 600.0f && f.y < 440.0f) features.push_back(f);
  }
  ASSERT_GT(features.size(), 100u);
  const TrackResult r = TemporalTracker().Track(ref, cur, features);
  ASSERT_EQ(r.points.size(), features.size());
  EXPECT_GT(r.kept, static_cast<int>(features.size()) * 9 / 10);
  EXPECT_EQ(r.kept + r.lost + r.fb_rejected, static_cast<int>(features.size()));
  for (size_t i = 0; i < features.size(); ++i) {
    if (r.tracked[i] == 0) continue;
    EXPECT_NEAR(r.points[i].x - features[i].x, 7.4f, 0.1f);
    EXPECT_NEAR(r.points[i].y - features[i].y, -3.2f, 0.1f);
  }
}

TEST(TemporalTrackerTest, BadFramesTrackNothing) {
  const cv::Mat ref = testing::RandomTexture(320, 240, 22, 2.0);
  const std::vector<cv::Point2f> pts = {{100.0f, 100.0f}, {200.0f, 120.0f}};
  const TemporalTracker tracker;
  EXPECT_EQ(tracker.Track(ref, cv::Mat(), pts).kept, 0);
  EXPECT_EQ(tracker.Track(ref, cv::Mat::zeros(120, 160, CV_8UC1), pts).kept, 0);
  EXPECT_EQ(tracker.Track(ref, cv::Mat::zeros(240, 320, CV_8UC1), pts).kept, 0);
  EXPECT_EQ(tracker.Track(ref, cv::Mat(240, 320, CV_8UC1, cv::Scalar(255)), pts).kept, 0);
  EXPECT_EQ(tracker.Track(ref, ref, {}).kept, 0);
}

}  // namespace
}  // namespace rover::estimator::vo
