#include "core/calib/stereo_rectifier.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace rover::calib {
namespace {

cv::Mat CameraMatrix(const CameraModel& c) {
  cv::Mat k = cv::Mat::eye(3, 3, CV_64F);
  k.at<double>(0, 0) = c.intrinsics[0];
  k.at<double>(1, 1) = c.intrinsics[1];
  k.at<double>(0, 2) = c.intrinsics[2];
  k.at<double>(1, 2) = c.intrinsics[3];
  return k;
}

cv::Mat Distortion(const CameraModel& c) {
  cv::Mat d(1, 4, CV_64F);
  for (int i = 0; i < 4; ++i) d.at<double>(0, i) = c.distortion[static_cast<size_t>(i)];
  return d;
}

bool Valid(const CameraModel& c) {
  return c.width_px > 0 && c.height_px > 0 && c.intrinsics[0] > 0.0 && c.intrinsics[1] > 0.0;
}

}  // namespace

std::optional<StereoRectifier> StereoRectifier::Create(const CameraModel& cam0,
                                                       const CameraModel& cam1,
                                                       const StereoRectifierOptions& options) {
  if (!Valid(cam0) || !Valid(cam1) || cam0.width_px != cam1.width_px ||
      cam0.height_px != cam1.height_px || cam0.distortion_model != cam1.distortion_model) {
    return std::nullopt;
  }
  // OpenCV rectifies a pair of one model only; the radial-tangential path is
  // the one the accuracy figures were measured with and stays call for call
  // as it was.
  const bool fisheye = cam0.distortion_model == DistortionModel::kEquidistant;
  // x_cam1 = R * x_cam0 + T.
  const Eigen::Isometry3d T_cam1_cam0 = cam1.T_body_cam.inverse() * cam0.T_body_cam;
  if (T_cam1_cam0.translation().norm() < 1e-6) return std::nullopt;
  cv::Mat r(3, 3, CV_64F);
  cv::Mat t(3, 1, CV_64F);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) r.at<double>(i, j) = T_cam1_cam0.linear()(i, j);
    t.at<double>(i, 0) = T_cam1_cam0.translation()(i);
  }
  StereoRectifier out;
  out.size_ = cv::Size(cam0.width_px, cam0.height_px);
  cv::Mat r0, r1, p0, p1, q;
  const cv::Mat k0 = CameraMatrix(cam0), k1 = CameraMatrix(cam1);
  const cv::Mat d0 = Distortion(cam0), d1 = Distortion(cam1);
  if (fisheye) {
    cv::fisheye::stereoRectify(k0, d0, k1, d1, out.size_, r, t, r0, r1, p0, p1, q,
                               cv::fisheye::CALIB_ZERO_DISPARITY, out.size_, options.alpha);
  } else {
    cv::stereoRectify(k0, d0, k1, d1, out.size_, r, t, r0, r1, p0, p1, q, cv::CALIB_ZERO_DISPARITY,
                      options.alpha, out.size_);
  }
  const double fx = p0.at<double>(0, 0);
  const double baseline = -p1.at<double>(0, 3) / fx;
  if (!(fx > 0.0) || !(baseline > 0.0) || !std::isfinite(baseline)) return std::nullopt;
  out.intrinsics_ = {fx, p0.at<double>(1, 1), p0.at<double>(0, 2), p0.at<double>(1, 2)};
  out.baseline_m_ = baseline;
  Eigen::Matrix3d R_rect_cam0, R_rect_cam1;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      R_rect_cam0(i, j) = r0.at<double>(i, j);
      R_rect_cam1(i, j) = r1.at<double>(i, j);
    }
  }
  out.flat_field_q8_[0] = FlatFieldGainQ8(cam0, R_rect_cam0, out.intrinsics_, out.size_);
  out.flat_field_q8_[1] = FlatFieldGainQ8(cam1, R_rect_cam1, out.intrinsics_, out.size_);
  Eigen::Isometry3d T_rect_cam0 = Eigen::Isometry3d::Identity();
  T_rect_cam0.linear() = R_rect_cam0;
  out.T_cam0rect_body_ = T_rect_cam0 * cam0.T_body_cam.inverse();
  if (fisheye) {
    cv::fisheye::initUndistortRectifyMap(k0, d0, r0, p0, out.size_, CV_16SC2, out.map_a_[0],
                                         out.map_b_[0]);
    cv::fisheye::initUndistortRectifyMap(k1, d1, r1, p1, out.size_, CV_16SC2, out.map_a_[1],
                                         out.map_b_[1]);
  } else {
    cv::initUndistortRectifyMap(k0, d0, r0, p0, out.size_, CV_16SC2, out.map_a_[0], out.map_b_[0]);
    cv::initUndistortRectifyMap(k1, d1, r1, p1, out.size_, CV_16SC2, out.map_a_[1], out.map_b_[1]);
  }
  return out;
}

cv::Mat StereoRectifier::FlatFieldGainQ8(const CameraModel& cam, const Eigen::Matrix3d& R_rect_cam,
                                         const RectifiedIntrinsics& k, cv::Size size) {
  const double v = cam.vignetting_cos4_strength;
  if (!(v > 0.0)) return {};
  cv::Mat gain(size, CV_16UC1);
  // A rectified pixel's ray, rotated back into the raw camera, gives the
  // angle theta the lens saw it at (no distortion model needed).
  const Eigen::Matrix3d R_cam_rect = R_rect_cam.transpose();
  for (int y = 0; y < size.height; ++y) {
    uint16_t* row = gain.ptr<uint16_t>(y);
    for (int x = 0; x < size.width; ++x) {
      const Eigen::Vector3d ray_cam =
          R_cam_rect * Eigen::Vector3d((x - k.cx) / k.fx, (y - k.cy) / k.fy, 1.0);
      const double cos_theta = std::max(0.0, ray_cam.z() / ray_cam.norm());
      const double brightness = 1.0 - v * (1.0 - std::pow(cos_theta, 4.0));
      row[x] = static_cast<uint16_t>(std::min(65535.0, std::round(256.0 / brightness)));
    }
  }
  return gain;
}

cv::Mat StereoRectifier::FlatFieldGain(int index) const {
  if (index < 0 || index > 1) return {};
  const cv::Mat& gain_q8 = flat_field_q8_[static_cast<size_t>(index)];
  if (gain_q8.empty()) return {};
  cv::Mat gain;
  gain_q8.convertTo(gain, CV_32F, 1.0 / 256.0);
  return gain;
}

bool StereoRectifier::RectifyOne(int index, const cv::Mat& raw, cv::Mat* rect) const {
  if (index < 0 || index > 1 || rect == nullptr || raw.empty() || raw.type() != CV_8UC1 ||
      raw.size() != size_) {
    return false;
  }
  const auto i = static_cast<size_t>(index);
  cv::remap(raw, *rect, map_a_[i], map_b_[i], cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
  const cv::Mat& gain = flat_field_q8_[i];
  if (gain.empty()) return true;
  for (int y = 0; y < rect->rows; ++y) {
    uint8_t* pixel = rect->ptr<uint8_t>(y);
    const uint16_t* g = gain.ptr<uint16_t>(y);
    for (int x = 0; x < rect->cols; ++x) {
      const uint32_t value = (static_cast<uint32_t>(pixel[x]) * g[x] + 128u) >> 8;
      pixel[x] = static_cast<uint8_t>(std::min<uint32_t>(value, 255u));
    }
  }
  return true;
}

bool StereoRectifier::Rectify(const cv::Mat& raw0, const cv::Mat& raw1, cv::Mat* rect0,
                              cv::Mat* rect1) const {
  for (const cv::Mat* m : {&raw0, &raw1}) {
    if (m->empty() || m->type() != CV_8UC1 || m->size() != size_) return false;
  }
  return RectifyOne(0, raw0, rect0) && RectifyOne(1, raw1, rect1);
}

}  // namespace rover::calib
