#include "mapping/tags/tag_pose.h"

#include <cmath>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

namespace rover::mapping {
namespace {

// Corner k of a tag of side s in its own frame (z = 0), in the order of
// TagDetection and of SOLVEPNP_IPPE_SQUARE.
Eigen::Vector3d TagCorner(std::size_t k, double s) {
  static constexpr double kSigns[4][2] = {{-1, 1}, {1, 1}, {1, -1}, {-1, -1}};
  return Eigen::Vector3d(kSigns[k][0] * s / 2, kSigns[k][1] * s / 2, 0.0);
}

double ReprojectionRmse(const Eigen::Isometry3d& T, const std::array<Eigen::Vector2d, 4>& corners,
                        double s, const calib::RectifiedIntrinsics& camera) {
  const std::array<Eigen::Vector2d, 4> p = ProjectTagCorners(T, s, camera);
  double sum = 0.0;
  for (std::size_t k = 0; k < 4; ++k) sum += (p[k] - corners[k]).squaredNorm();
  return std::sqrt(sum / 4.0);
}

Eigen::Isometry3d FromRvecTvec(const cv::Mat& rvec, const cv::Mat& tvec) {
  cv::Mat R;
  cv::Rodrigues(rvec, R);
  Eigen::Matrix3d R_e;
  Eigen::Vector3d t_e;
  cv::cv2eigen(R, R_e);
  cv::cv2eigen(tvec, t_e);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R_e;
  T.translation() = t_e;
  return T;
}

}  // namespace

std::array<Eigen::Vector2d, 4> ProjectTagCorners(const Eigen::Isometry3d& T_camera_tag,
                                                 double tag_size_m,
                                                 const calib::RectifiedIntrinsics& camera) {
  std::array<Eigen::Vector2d, 4> out;
  for (std::size_t k = 0; k < 4; ++k) {
    const Eigen::Vector3d p = T_camera_tag * TagCorner(k, tag_size_m);
    out[k] = Eigen::Vector2d(camera.fx * p.x() / p.z() + camera.cx,
                             camera.fy * p.y() / p.z() + camera.cy);
  }
  return out;
}

std::optional<TagPose> EstimateTagPose(const std::array<Eigen::Vector2d, 4>& corners_px,
                                       double tag_size_m, const calib::RectifiedIntrinsics& camera,
                                       std::string* error) {
  const auto fail = [&](const std::string& why) -> std::optional<TagPose> {
    if (error) *error = "tag pose: " + why;
    return std::nullopt;
  };
  if (!(std::isfinite(tag_size_m) && tag_size_m > 0.0)) {
    return fail("expected a tag size > 0 m, found " + std::to_string(tag_size_m));
  }
  if (!(camera.fx > 0.0 && camera.fy > 0.0 && std::isfinite(camera.cx) &&
        std::isfinite(camera.cy) && std::isfinite(camera.fx) && std::isfinite(camera.fy))) {
    return fail("expected finite intrinsics with positive focal lengths");
  }
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  for (std::size_t k = 0; k < 4; ++k) {
    if (!corners_px[k].allFinite()) return fail("corner " + std::to_string(k) + " is not finite");
    const Eigen::Vector3d c = TagCorner(k, tag_size_m);
    object.emplace_back(c.x(), c.y(), c.z());
    image.emplace_back(corners_px[k].x(), corners_px[k].y());
  }
  const cv::Matx33d K(camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1);
  // IPPE for squares first; on exactly symmetric corners its homography
  // can come out NaN, and the general planar IPPE (same two solutions) then
  // stands in.
  std::vector<TagPoseSolution> found;
  for (const int method : {cv::SOLVEPNP_IPPE_SQUARE, cv::SOLVEPNP_IPPE}) {
    std::vector<cv::Mat> rvecs;
    std::vector<cv::Mat> tvecs;
    try {
      cv::solvePnPGeneric(object, image, K, cv::noArray(), rvecs, tvecs, false,
                          static_cast<cv::SolvePnPMethod>(method));
    } catch (const cv::Exception& e) {
      return fail(std::string("the solver failed: ") + e.what());
    }
    for (std::size_t i = 0; i < rvecs.size() && i < tvecs.size(); ++i) {
      TagPoseSolution s;
      s.T_camera_tag = FromRvecTvec(rvecs[i], tvecs[i]);
      if (!s.T_camera_tag.matrix().allFinite() || s.T_camera_tag.translation().z() <= 0.0) continue;
      s.reprojection_rmse_px = ReprojectionRmse(s.T_camera_tag, corners_px, tag_size_m, camera);
      found.push_back(s);
    }
    if (!found.empty()) break;
  }
  if (found.empty()) return fail("no solution lies in front of the camera");
  if (found.size() > 1 && found[1].reprojection_rmse_px < found[0].reprojection_rmse_px) {
    std::swap(found[0], found[1]);
  }
  TagPose pose;
  pose.best = found[0];
  // A single solution (the library's degenerate case) is its own alternative.
  pose.alternative = found.size() > 1 ? found[1] : found[0];
  const double alt = pose.alternative.reprojection_rmse_px;
  pose.ambiguity_ratio = alt > 0.0 ? pose.best.reprojection_rmse_px / alt : 1.0;
  pose.distance_m = pose.best.T_camera_tag.translation().norm();
  pose.tilt_rad = TagTilt(pose.best.T_camera_tag);
  return pose;
}

double TagTilt(const Eigen::Isometry3d& T_camera_tag) {
  // The tag's z points into the tag, away from a camera that reads it.
  const Eigen::Vector3d normal_to_camera = -T_camera_tag.linear().col(2);
  const Eigen::Vector3d to_camera = -T_camera_tag.translation().normalized();
  const double cos_tilt = std::clamp(normal_to_camera.dot(to_camera), -1.0, 1.0);
  const Eigen::Vector3d across = normal_to_camera - cos_tilt * to_camera;
  return std::acos(cos_tilt) * (across.x() >= 0.0 ? 1.0 : -1.0);
}

}  // namespace rover::mapping
