// The VO front-end stages on real EuRoC V1_01 frames (ROVER_SHARED_DIR).

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

#include "core/calib/stereo_rectifier.h"
#include "core/geometry/so3.h"
#include "drivers/replay/euroc_dataset.h"
#include "estimator/vo/feature_detector.h"
#include "estimator/vo/motion_estimator.h"
#include "estimator/vo/stereo_matcher.h"
#include "estimator/vo/temporal_tracker.h"
#include "tests/estimator/vo/euroc_vo_util.h"

namespace rover::estimator::vo {
namespace {

using Clock = std::chrono::steady_clock;

double Ms(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

class EurocVoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const char* shared = std::getenv("ROVER_SHARED_DIR");
    const std::string dir =
        std::string(shared != nullptr ? shared : "../shared") + "/data/euroc_v1_01_micro";
    dataset_ = drivers::EurocDataset::Load(dir, dir + "/groundtruth/V1_01_easy_openvins.csv");
    auto rect = calib::StereoRectifier::Create(dataset_.cam0(), dataset_.cam1());
    ASSERT_TRUE(rect.has_value());
    rectifier_ = std::move(*rect);
  }

  void Load(size_t i, cv::Mat* left, cv::Mat* right) const {
    const auto& f = dataset_.stereo_frames().at(i);
    const cv::Mat raw0 = cv::imread(f.cam0_path, cv::IMREAD_GRAYSCALE);
    const cv::Mat raw1 = cv::imread(f.cam1_path, cv::IMREAD_GRAYSCALE);
    ASSERT_TRUE(rectifier_->Rectify(raw0, raw1, left, right));
  }

  void RunPair(size_t ref, size_t cur);
  drivers::EurocDataset dataset_;
  std::optional<calib::StereoRectifier> rectifier_;
};

TEST_F(EurocVoTest, StereoMatchingFindsPlausibleDepths) {
  cv::Mat left, right;
  const auto t0 = Clock::now();
  Load(0, &left, &right);
  const auto t1 = Clock::now();
  const auto features = FeatureDetector().Detect(left);
  const auto t2 = Clock::now();
  const StereoMatcher matcher(rectifier_->intrinsics(), rectifier_->baseline_m());
  StereoMatchStats stats;
  const auto points = matcher.Match(left, right, features, &stats);
  const auto t3 = Clock::now();
  std::cout << "read+rectify " << Ms(t0, t1) << " ms, detect " << Ms(t1, t2) << " ms ("
            << features.size() << " features), stereo " << Ms(t2, t3) << " ms (" << points.size()
            << " points; search " << stats.search_rejected << ", lr " << stats.consistency_rejected
            << ", row " << stats.row_rejected << ", disparity " << stats.disparity_rejected
            << ", sigma " << stats.depth_sigma_rejected << ")\n";
  EXPECT_GT(features.size(), 200u);
  EXPECT_GT(points.size(), 150u);
  std::vector<double> depth;
  for (const auto& p : points) {
    EXPECT_GT(p.p_cam0rect.z(), 0.3);
    EXPECT_LT(p.p_cam0rect.z(), 20.0);
    depth.push_back(p.p_cam0rect.z());
  }
  std::nth_element(depth.begin(), depth.begin() + static_cast<long>(depth.size() / 2), depth.end());
  const double median = depth[depth.size() / 2];
  std::cout << "median depth " << median << " m\n";
  EXPECT_GT(median, 1.0);  // the Vicon room: walls a few metres away
  EXPECT_LT(median, 8.0);
}

TEST_F(EurocVoTest, MotionBetweenNearbyFramesMatchesGroundTruth) {
  // The excerpt is the hovering start of V1_01: the body moves only by
  // millimetres and tenths of a degree, so these are small motions.
  RunPair(0, 10);
  RunPair(50, 54);
  RunPair(50, 58);
  RunPair(80, 94);
}

void EurocVoTest::RunPair(size_t ref, size_t cur) {
  cv::Mat l0, r0, l1, r1;
  Load(ref, &l0, &r0);
  Load(cur, &l1, &r1);
  const StereoMatcher matcher(rectifier_->intrinsics(), rectifier_->baseline_m());
  const auto features = FeatureDetector().Detect(l0);
  const auto points = matcher.Match(l0, r0, features);
  ASSERT_GT(points.size(), 100u);

  // Keyframe -> current by KLT, then stereo matching in the current pair.
  const auto t0 = Clock::now();
  std::vector<cv::Point2f> prev;
  for (const auto& p : points) prev.push_back(p.left);
  const TrackResult track = TemporalTracker().Track(l0, l1, prev);
  std::vector<cv::Point2f> tracked;
  std::vector<size_t> tracked_point;
  for (size_t i = 0; i < prev.size(); ++i) {
    if (track.tracked[i] != 0) {
      tracked.push_back(track.points[i]);
      tracked_point.push_back(i);
    }
  }
  EXPECT_GT(track.kept, static_cast<int>(prev.size()) * 8 / 10);
  const auto current = matcher.Match(l1, r1, tracked);
  std::vector<StereoObservation> obs;
  for (const auto& c : current) {
    StereoObservation o;
    o.p_ref = points[tracked_point[static_cast<size_t>(c.feature_index)]].p_cam0rect;
    o.left = {c.left.x, c.left.y};
    o.right = {c.right.x, c.right.y};
    obs.push_back(o);
  }
  const auto t1 = Clock::now();
  const MotionEstimator estimator(rectifier_->intrinsics(), rectifier_->baseline_m(),
                                  rectifier_->image_size());
  const MotionEstimate est = estimator.Estimate(obs);
  const auto t2 = Clock::now();
  ASSERT_TRUE(est.valid);
  std::cout << "track " << track.kept << "/" << prev.size() << " + stereo " << Ms(t0, t1) << " ms ("
            << obs.size() << " observations), "
            << "motion " << Ms(t1, t2) << " ms (" << est.inliers.size() << " inliers, "
            << est.ransac_iterations << " RANSAC, " << est.lm_iterations << " LM, rms "
            << est.rms_error_px << " px, spread " << est.spread << ")\n";
  EXPECT_GT(est.inliers.size(), 60u);
  EXPECT_LT(est.rms_error_px, 1.0);

  RelativePoseMeasurement m =
      ToBodyRelativePose(est.T_cur_ref, est.covariance, rectifier_->T_body_cam0rect());
  const auto& frames = dataset_.stereo_frames();
  const auto g0 = dataset_.GroundTruthAt(frames[ref].stamp);
  const auto g1 = dataset_.GroundTruthAt(frames[cur].stamp);
  ASSERT_TRUE(g0.has_value() && g1.has_value());
  const Eigen::Matrix3d R0 = g0->q_world_body.toRotationMatrix();
  const Eigen::Vector3d p_true = R0.transpose() * (g1->p_world_body - g0->p_world_body);
  const Eigen::Matrix3d R_true = R0.transpose() * g1->q_world_body.toRotationMatrix();
  const Eigen::Vector3d dp = m.p_from_to - p_true;
  const Eigen::Vector3d dth = LogSO3(R_true.transpose() * m.q_from_to.toRotationMatrix());
  std::cout << ref << "->" << cur << ": true motion " << p_true.norm() << " m, "
            << LogSO3(R_true).norm() * 57.3 << " deg; error " << dp.norm() << " m, "
            << dth.norm() * 57.3 << " deg; sigma_p "
            << std::sqrt(m.covariance.topLeftCorner<3, 3>().trace()) << " m, sigma_theta "
            << std::sqrt(m.covariance.bottomRightCorner<3, 3>().trace()) * 57.3 << " deg\n";
  EXPECT_LT(m.p_from_to.norm(), 0.05);
  EXPECT_LT(dp.norm(), 0.005);
  EXPECT_LT(dth.norm(), 0.1 / 57.3);
}

TEST_F(EurocVoTest, BlackAndOverExposedFramesGiveNothing) {
  cv::Mat left, right;
  Load(0, &left, &right);
  const cv::Mat black = cv::Mat::zeros(left.size(), CV_8UC1);
  const cv::Mat white(left.size(), CV_8UC1, cv::Scalar(255));
  EXPECT_TRUE(FeatureDetector().Detect(black).empty());
  EXPECT_TRUE(FeatureDetector().Detect(white).empty());
  const StereoMatcher matcher(rectifier_->intrinsics(), rectifier_->baseline_m());
  const auto features = FeatureDetector().Detect(left);
  EXPECT_TRUE(matcher.Match(left, black, features).size() < features.size() / 10);
  EXPECT_TRUE(matcher.Match(left, cv::Mat(), features).empty());
}

}  // namespace
}  // namespace rover::estimator::vo
