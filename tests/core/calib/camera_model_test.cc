#include "core/calib/camera_model.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace rover::calib {
namespace {

using ::testing::HasSubstr;

// EuRoC V1 cam0 (strong barrel distortion, k1 = -0.28).
CameraModel RadTanCam() {
  CameraModel c;
  c.width_px = 752;
  c.height_px = 480;
  c.rate_hz = 20.0;
  c.intrinsics = {458.654, 457.296, 367.215, 248.375};
  c.distortion = {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05};
  return c;
}

// A 190-degree-class fisheye (TUM VI's cam0 coefficients).
CameraModel FisheyeCam() {
  CameraModel c;
  c.width_px = 512;
  c.height_px = 512;
  c.rate_hz = 20.0;
  c.distortion_model = DistortionModel::kEquidistant;
  c.intrinsics = {190.978, 190.973, 254.932, 256.897};
  c.distortion = {0.0034823894022493434, 0.0007150348452162257, -0.0020532361418706202,
                  0.00020293673591811182};
  return c;
}

// Random camera-frame points within `max_angle_rad` of the optical axis, at
// 0.5-20 m.
std::vector<Eigen::Vector3d> RandomPoints(double max_angle_rad, int count, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> angle(0.0, max_angle_rad);
  std::uniform_real_distribution<double> azimuth(-M_PI, M_PI);
  std::uniform_real_distribution<double> range(0.5, 20.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < count; ++i) {
    const double a = angle(rng), phi = azimuth(rng);
    points.push_back(range(rng) * Eigen::Vector3d(std::sin(a) * std::cos(phi),
                                                  std::sin(a) * std::sin(phi), std::cos(a)));
  }
  return points;
}

// The pixels OpenCV computes for `points` with the model's lens.
std::vector<cv::Point2d> OpenCvProject(const CameraModel& c,
                                       const std::vector<Eigen::Vector3d>& points) {
  std::vector<cv::Point3d> in;
  for (const Eigen::Vector3d& p : points) in.emplace_back(p.x(), p.y(), p.z());
  const cv::Matx33d k(c.intrinsics[0], 0, c.intrinsics[2], 0, c.intrinsics[1], c.intrinsics[3], 0,
                      0, 1);
  const cv::Vec4d d(c.distortion[0], c.distortion[1], c.distortion[2], c.distortion[3]);
  std::vector<cv::Point2d> out;
  if (c.distortion_model == DistortionModel::kEquidistant) {
    cv::fisheye::projectPoints(in, out, cv::Vec3d::zeros(), cv::Vec3d::zeros(), k, d);
  } else {
    cv::projectPoints(in, cv::Vec3d::zeros(), cv::Vec3d::zeros(), k, d, out);
  }
  return out;
}

void ExpectProjectionLikeOpenCv(const CameraModel& c, double max_angle_rad) {
  const std::vector<Eigen::Vector3d> points = RandomPoints(max_angle_rad, 2000, 7);
  const std::vector<cv::Point2d> expected = OpenCvProject(c, points);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::optional<Eigen::Vector2d> u = c.Project(points[i]);
    ASSERT_TRUE(u.has_value()) << points[i].transpose();
    EXPECT_NEAR(u->x(), expected[i].x, 1e-9) << points[i].transpose();
    EXPECT_NEAR(u->y(), expected[i].y, 1e-9) << points[i].transpose();
  }
}

// Also checks Project(Unproject(pixel)) == pixel on a grid over the image,
// for pixels up to `max_radius` from the principal point in normalised
// distorted coordinates (a fisheye image's corners see rays from behind the
// camera plane, which Project() does not take).
void ExpectUnprojectInvertsProject(const CameraModel& c, double max_angle_rad,
                                   double max_radius = INFINITY) {
  for (const Eigen::Vector3d& p : RandomPoints(max_angle_rad, 2000, 11)) {
    const std::optional<Eigen::Vector2d> u = c.Project(p);
    ASSERT_TRUE(u.has_value());
    const std::optional<Eigen::Vector3d> bearing = c.Unproject(*u);
    ASSERT_TRUE(bearing.has_value()) << "pixel " << u->transpose();
    EXPECT_NEAR(bearing->norm(), 1.0, 1e-12);
    EXPECT_LT((*bearing - p.normalized()).norm(), 1e-10) << "point " << p.transpose();
  }
  // And the other way round, over the whole image.
  for (int v = 0; v < c.height_px; v += 16) {
    for (int u = 0; u < c.width_px; u += 16) {
      const Eigen::Vector2d pixel(u, v);
      const Eigen::Vector2d m((u - c.intrinsics[2]) / c.intrinsics[0],
                              (v - c.intrinsics[3]) / c.intrinsics[1]);
      if (m.norm() > max_radius) continue;
      const std::optional<Eigen::Vector3d> bearing = c.Unproject(pixel);
      ASSERT_TRUE(bearing.has_value()) << "pixel " << pixel.transpose();
      const std::optional<Eigen::Vector2d> back = c.Project(*bearing);
      ASSERT_TRUE(back.has_value());
      EXPECT_LT((*back - pixel).norm(), 1e-8) << "pixel " << pixel.transpose();
    }
  }
}

TEST(CameraModelTest, RadialTangentialProjectsLikeOpenCv) {
  ExpectProjectionLikeOpenCv(RadTanCam(), 0.7);
}

TEST(CameraModelTest, EquidistantProjectsLikeOpenCvFisheye) {
  ExpectProjectionLikeOpenCv(FisheyeCam(), 1.4);
}

TEST(CameraModelTest, RadialTangentialUnprojectInvertsProject) {
  ExpectUnprojectInvertsProject(RadTanCam(), 0.7);
}

TEST(CameraModelTest, EquidistantUnprojectInvertsProject) {
  // theta_d(pi / 2) is 1.5545 for this lens.
  ExpectUnprojectInvertsProject(FisheyeCam(), 1.4, 1.55);
}

TEST(CameraModelTest, PointsNotInFrontAreNotProjected) {
  for (const CameraModel& c : {RadTanCam(), FisheyeCam()}) {
    EXPECT_FALSE(c.Project(Eigen::Vector3d(0.1, 0.2, 0.0)).has_value());
    EXPECT_FALSE(c.Project(Eigen::Vector3d(0.1, 0.2, -1.0)).has_value());
    EXPECT_FALSE(c.Project(Eigen::Vector3d(NAN, 0.2, 1.0)).has_value());
    // The principal point is the optical axis.
    const Eigen::Vector2d centre(c.intrinsics[2], c.intrinsics[3]);
    EXPECT_LT((*c.Project(Eigen::Vector3d(0, 0, 2)) - centre).norm(), 1e-12);
    EXPECT_LT((*c.Unproject(centre) - Eigen::Vector3d::UnitZ()).norm(), 1e-12);
  }
}

TEST(CameraModelTest, UnprojectRefusesPixelsPastTheFold) {
  // r_d = r (1 - 0.5 r^2) peaks at r_d = 0.544 (r = 0.816): no ray is seen
  // farther out.
  CameraModel c = RadTanCam();
  c.distortion = {-0.5, 0.0, 0.0, 0.0};
  EXPECT_TRUE(c.Unproject(Eigen::Vector2d(c.intrinsics[2] + 0.5 * c.intrinsics[0], c.intrinsics[3]))
                  .has_value());
  EXPECT_FALSE(
      c.Unproject(Eigen::Vector2d(c.intrinsics[2] + 0.6 * c.intrinsics[0], c.intrinsics[3]))
          .has_value());
  CameraModel f = FisheyeCam();
  f.distortion = {-0.3, 0.0, 0.0, 0.0};  // theta_d peaks at 0.703 (theta = 1.054)
  EXPECT_TRUE(
      f.Unproject(Eigen::Vector2d(f.intrinsics[2] + 0.65 * f.intrinsics[0], f.intrinsics[3]))
          .has_value());
  EXPECT_FALSE(
      f.Unproject(Eigen::Vector2d(f.intrinsics[2] + 0.75 * f.intrinsics[0], f.intrinsics[3]))
          .has_value());
}

std::string ProblemOf(const CameraModel& c) {
  try {
    c.Validate();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "<valid>";
}

TEST(CameraModelTest, ValidateNamesTheBadField) {
  EXPECT_EQ(ProblemOf(RadTanCam()), "<valid>");
  EXPECT_EQ(ProblemOf(FisheyeCam()), "<valid>");
  CameraModel c = RadTanCam();
  c.width_px = 0;
  EXPECT_EQ(ProblemOf(c), "width_px: expected > 0 px, found 0");
  c = RadTanCam();
  c.height_px = -480;
  EXPECT_EQ(ProblemOf(c), "height_px: expected > 0 px, found -480");
  c = RadTanCam();
  c.rate_hz = 0.0;
  EXPECT_EQ(ProblemOf(c), "rate_hz: expected a frame rate > 0 Hz, found 0");
  c = RadTanCam();
  c.intrinsics[1] = -457.296;
  EXPECT_EQ(ProblemOf(c),
            "intrinsics: expected focal lengths fu, fv > 0 px, found fu = 458.654, fv = -457.296");
  c = RadTanCam();
  c.intrinsics[2] = INFINITY;
  EXPECT_THAT(ProblemOf(c), HasSubstr("intrinsics: expected finite"));
  c = RadTanCam();
  c.distortion[3] = NAN;
  EXPECT_THAT(ProblemOf(c), HasSubstr("distortion: expected finite coefficients"));
  c = RadTanCam();
  c.T_body_cam.linear() *= 1.001;
  EXPECT_THAT(ProblemOf(c), HasSubstr("T_body_cam: expected an orthonormal rotation part"));
  c = RadTanCam();
  c.T_body_cam.linear() = Eigen::Vector3d(1, 1, -1).asDiagonal();
  EXPECT_THAT(ProblemOf(c), HasSubstr("T_body_cam: expected a proper rotation (det R = +1)"));
  c = RadTanCam();
  c.T_body_cam.matrix()(3, 0) = 0.5;
  EXPECT_EQ(ProblemOf(c), "T_body_cam: expected the last row 0 0 0 1, found 0.5 0 0 1");
  c = RadTanCam();
  c.vignetting_cos4_strength = 1.0;
  EXPECT_EQ(ProblemOf(c), "vignetting_cos4_strength: expected a strength in [0, 1), found 1");
  c.vignetting_cos4_strength = NAN;
  EXPECT_THAT(ProblemOf(c), HasSubstr("vignetting_cos4_strength: expected a strength"));
}

TEST(CameraModelTest, EqualityComparesEveryField) {
  const CameraModel a = RadTanCam();
  CameraModel b = a;
  EXPECT_EQ(a, b);
  b.distortion_model = DistortionModel::kEquidistant;
  EXPECT_NE(a, b);
  b = a;
  b.T_body_cam.translation().x() = 1e-300;
  EXPECT_NE(a, b);
  b = a;
  b.rate_hz = 30.0;
  EXPECT_NE(a, b);
  b = a;
  b.vignetting_cos4_strength = 0.3;
  EXPECT_NE(a, b);
}

TEST(CameraModelTest, EurocDistortionNames) {
  EXPECT_EQ(EurocDistortionName(DistortionModel::kRadialTangential), "radial-tangential");
  EXPECT_EQ(EurocDistortionName(DistortionModel::kEquidistant), "equidistant");
}

}  // namespace
}  // namespace rover::calib
