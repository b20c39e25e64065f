#include "core/calib/stereo_rectifier.h"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>

#include "core/geometry/so3.h"

namespace rover::calib {
namespace {

// EuRoC V1 calibration (cam0, cam1 sensor.yaml), as plain numbers.
CameraModel EurocCam(int index) {
  CameraModel c;
  c.width_px = 752;
  c.height_px = 480;
  Eigen::Matrix4d m;
  if (index == 0) {
    c.intrinsics = {458.654, 457.296, 367.215, 248.375};
    c.distortion = {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05};
    m << 0.0148655429818, -0.999880929698, 0.00414029679422, -0.0216401454975, 0.999557249008,
        0.0149672133247, 0.025715529948, -0.064676986768, -0.0257744366974, 0.00375618835797,
        0.999660727178, 0.00981073058949, 0.0, 0.0, 0.0, 1.0;
  } else {
    c.intrinsics = {457.587, 456.134, 379.999, 255.238};
    c.distortion = {-0.28368365, 0.07451284, -0.00010473, -3.55590700e-05};
    m << 0.0125552670891, -0.999755099723, 0.0182237714554, -0.0198435579556, 0.999598781151,
        0.0130119051815, 0.0251588363115, 0.0453689425024, -0.0253898008918, 0.0179005838253,
        0.999517347078, 0.00786212447038, 0.0, 0.0, 0.0, 1.0;
  }
  c.T_body_cam.matrix() = m;
  return c;
}

// The EuRoC geometry with an equidistant (fisheye) lens of mild distortion.
CameraModel FisheyeCam(int index) {
  CameraModel c = EurocCam(index);
  c.distortion_model = DistortionModel::kEquidistant;
  c.distortion = index == 0 ? std::array<double, 4>{0.012, -0.004, 0.0015, -0.0003}
                            : std::array<double, 4>{0.010, -0.003, 0.0011, -0.0002};
  return c;
}

// Projects a body-frame point into a raw (distorted) camera image, through
// OpenCV rather than the model under test.
Eigen::Vector2d ProjectRaw(const CameraModel& c, const Eigen::Vector3d& p_body) {
  const Eigen::Vector3d p = c.T_body_cam.inverse() * p_body;
  std::vector<cv::Point3d> in = {{p.x(), p.y(), p.z()}};
  std::vector<cv::Point2d> out;
  const cv::Matx33d k(c.intrinsics[0], 0, c.intrinsics[2], 0, c.intrinsics[1], c.intrinsics[3], 0,
                      0, 1);
  const cv::Vec4d d(c.distortion[0], c.distortion[1], c.distortion[2], c.distortion[3]);
  if (c.distortion_model == DistortionModel::kEquidistant) {
    cv::fisheye::projectPoints(in, out, cv::Vec3d::zeros(), cv::Vec3d::zeros(), k, d);
  } else {
    cv::projectPoints(in, cv::Vec3d::zeros(), cv::Vec3d::zeros(), k, d, out);
  }
  return {out[0].x, out[0].y};
}

// Checks the rectified geometry of a EuRoC-like head and that a body point
// projected through the raw cameras and rectified lands where the rectified
// model predicts, on the same row in both images.
void ExpectRectifiedGeometry(const CameraModel& c0, const CameraModel& c1) {
  const auto rect = StereoRectifier::Create(c0, c1);
  ASSERT_TRUE(rect.has_value());
  EXPECT_NEAR(rect->baseline_m(), 0.110, 0.002);
  EXPECT_GT(rect->intrinsics().fx, 300.0);
  EXPECT_EQ(rect->intrinsics().fx, rect->intrinsics().fy);
  // The rectified frame is only slightly rotated from cam0.
  const Eigen::Matrix3d R = rect->T_cam0rect_body().linear() * c0.T_body_cam.linear();
  EXPECT_LT(LogSO3(R).norm(), 0.05);
  EXPECT_LT((rect->T_body_cam0rect().translation() - c0.T_body_cam.translation()).norm(), 1e-9);

  cv::Mat raw0 = cv::Mat::zeros(480, 752, CV_8UC1), raw1 = raw0.clone();
  const Eigen::Vector3d p_body = c0.T_body_cam * Eigen::Vector3d(0.3, -0.2, 3.0);
  const Eigen::Vector2d u0 = ProjectRaw(c0, p_body), u1 = ProjectRaw(c1, p_body);
  cv::circle(raw0,
             cv::Point(static_cast<int>(std::lround(u0.x() * 16)),
                       static_cast<int>(std::lround(u0.y() * 16))),
             4 * 16, cv::Scalar(255), cv::FILLED, cv::LINE_AA, 4);
  cv::circle(raw1,
             cv::Point(static_cast<int>(std::lround(u1.x() * 16)),
                       static_cast<int>(std::lround(u1.y() * 16))),
             4 * 16, cv::Scalar(255), cv::FILLED, cv::LINE_AA, 4);
  cv::Mat r0, r1;
  ASSERT_TRUE(rect->Rectify(raw0, raw1, &r0, &r1));
  const auto centroid = [](const cv::Mat& m) {
    const cv::Moments mo = cv::moments(m);
    return Eigen::Vector2d(mo.m10 / mo.m00, mo.m01 / mo.m00);
  };
  const Eigen::Vector3d p = rect->T_cam0rect_body() * p_body;
  const auto& k = rect->intrinsics();
  const Eigen::Vector2d expected0(k.fx * p.x() / p.z() + k.cx, k.fy * p.y() / p.z() + k.cy);
  const Eigen::Vector2d expected1(k.fx * (p.x() - rect->baseline_m()) / p.z() + k.cx,
                                  expected0.y());
  EXPECT_LT((centroid(r0) - expected0).norm(), 0.3);
  EXPECT_LT((centroid(r1) - expected1).norm(), 0.3);
}

TEST(StereoRectifierTest, EurocGeometry) { ExpectRectifiedGeometry(EurocCam(0), EurocCam(1)); }

TEST(StereoRectifierTest, EquidistantGeometry) {
  ExpectRectifiedGeometry(FisheyeCam(0), FisheyeCam(1));
}

// A uniformly lit scene seen through a lens that vignettes: the raw image
// darkens towards its edges as 1 - v (1 - cos^4 theta).
cv::Mat VignettedFlatScene(const CameraModel& c, double strength, double level) {
  cv::Mat raw(c.height_px, c.width_px, CV_8UC1);
  for (int y = 0; y < raw.rows; ++y) {
    for (int x = 0; x < raw.cols; ++x) {
      const std::optional<Eigen::Vector3d> ray = c.Unproject(Eigen::Vector2d(x, y));
      const double cos_theta = ray ? ray->z() / ray->norm() : 0.0;
      raw.at<uint8_t>(y, x) =
          cv::saturate_cast<uint8_t>(level * (1.0 - strength * (1.0 - std::pow(cos_theta, 4))));
    }
  }
  return raw;
}

TEST(StereoRectifierTest, UndoesTheCalibratedVignetting) {
  constexpr double kStrength = 0.5, kLevel = 160.0;
  CameraModel c0 = EurocCam(0), c1 = EurocCam(1);
  const cv::Mat raw0 = VignettedFlatScene(c0, kStrength, kLevel);
  const cv::Mat raw1 = VignettedFlatScene(c1, kStrength, kLevel);
  // Without the vignetting in the calibration the corners stay dark.
  const auto flat = StereoRectifier::Create(c0, c1);
  ASSERT_TRUE(flat.has_value());
  cv::Mat rect0, rect1;
  ASSERT_TRUE(flat->Rectify(raw0, raw1, &rect0, &rect1));
  EXPECT_LT(rect0.at<uint8_t>(20, 20), kLevel - 20);
  // With it, the rectified images are flat (the valid region: alpha 0).
  c0.vignetting_cos4_strength = c1.vignetting_cos4_strength = kStrength;
  const auto corrected = StereoRectifier::Create(c0, c1);
  ASSERT_TRUE(corrected.has_value());
  ASSERT_TRUE(corrected->Rectify(raw0, raw1, &rect0, &rect1));
  for (const cv::Mat* rect : {&rect0, &rect1}) {
    for (int y = 10; y < rect->rows - 10; y += 7) {
      for (int x = 10; x < rect->cols - 10; x += 7) {
        ASSERT_NEAR(rect->at<uint8_t>(y, x), kLevel, 2.0) << "at x " << x << ", y " << y;
      }
    }
  }
  // The gain it applied, per pixel: what a raw pixel was multiplied by.
  EXPECT_TRUE(flat->FlatFieldGain(0).empty());
  EXPECT_TRUE(corrected->FlatFieldGain(2).empty());
  for (int i = 0; i < 2; ++i) {
    const cv::Mat gain = corrected->FlatFieldGain(i);
    ASSERT_EQ(gain.type(), CV_32FC1);
    ASSERT_EQ(gain.size(), corrected->image_size());
    const cv::Mat raw = VignettedFlatScene(i == 0 ? c0 : c1, kStrength, kLevel);
    cv::Mat dark;
    ASSERT_TRUE(flat->RectifyOne(i, raw, &dark));
    for (const cv::Point at : {cv::Point(20, 20), cv::Point(dark.cols / 2, dark.rows / 2)}) {
      EXPECT_NEAR(dark.at<uint8_t>(at) * gain.at<float>(at), kLevel, 2.5) << "camera " << i;
    }
    EXPECT_GT(gain.at<float>(20, 20), 1.2f);
  }
}

TEST(StereoRectifierTest, RejectsMixedDistortionModels) {
  // OpenCV rectifies a pair of one model only.
  EXPECT_FALSE(StereoRectifier::Create(EurocCam(0), FisheyeCam(1)).has_value());
  EXPECT_FALSE(StereoRectifier::Create(FisheyeCam(0), EurocCam(1)).has_value());
}

TEST(StereoRectifierTest, RejectsBadCalibrationAndImages) {
  CameraModel c0 = EurocCam(0), c1 = EurocCam(1);
  CameraModel same = c0;
  EXPECT_FALSE(StereoRectifier::Create(c0, same).has_value());
  CameraModel small = c1;
  small.width_px = 640;
  EXPECT_FALSE(StereoRectifier::Create(c0, small).has_value());
  CameraModel no_focal = c1;
  no_focal.intrinsics[0] = 0.0;
  EXPECT_FALSE(StereoRectifier::Create(c0, no_focal).has_value());

  const auto rect = StereoRectifier::Create(c0, c1);
  ASSERT_TRUE(rect.has_value());
  cv::Mat out0, out1;
  const cv::Mat good = cv::Mat::zeros(480, 752, CV_8UC1);
  EXPECT_FALSE(rect->Rectify(good, cv::Mat(), &out0, &out1));
  EXPECT_FALSE(rect->Rectify(cv::Mat::zeros(480, 640, CV_8UC1), good, &out0, &out1));
  EXPECT_FALSE(rect->Rectify(good, cv::Mat::zeros(480, 752, CV_16UC1), &out0, &out1));
  EXPECT_FALSE(rect->RectifyOne(2, good, &out0));
  EXPECT_TRUE(rect->Rectify(good, good, &out0, &out1));
}

}  // namespace
}  // namespace rover::calib
