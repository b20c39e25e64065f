#include "mapping/slam/frame_switch_noise.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/config/config.h"

namespace rover::mapping {
namespace {

Eigen::Matrix4d FilterCovariance() {
  Eigen::Matrix4d C = Eigen::Matrix4d::Zero();
  C.diagonal() << 1e-6, 2e-6, 3e-6, 1e-7;
  C(0, 3) = C(3, 0) = 2e-7;
  return C;
}

TEST(FrameSwitchNoiseTest, WithoutOdometryErrorTheFilterCovarianceIsScaledOnly) {
  FrameSwitchNoiseOptions o;
  o.filter_sigma_scale = 3.0;
  o.along_sigma_per_m = o.across_sigma_per_m = o.yaw_sigma_rad_per_m = 0.0;
  const Eigen::Matrix4d C = FrameSwitchCovariance(FilterCovariance(), {7.0, 0.0, 0.0}, o);
  EXPECT_TRUE(C.isApprox(9.0 * FilterCovariance(), 1e-12));
}

TEST(FrameSwitchNoiseTest, ErrorGrowsWithDistanceAlongAndAcrossTheDisplacement) {
  FrameSwitchNoiseOptions o;
  o.along_sigma_per_m = 0.0025;
  o.across_sigma_per_m = 0.0012;
  o.yaw_sigma_rad_per_m = 2.6e-4;
  const Eigen::Vector3d p_old_new_m(6.0, 8.0, 0.0);  // 10 m at 53 deg
  const Eigen::Matrix4d added =
      FrameSwitchCovariance(FilterCovariance(), p_old_new_m, o) - FilterCovariance();
  const Eigen::Vector3d u = p_old_new_m.normalized();
  const Eigen::Vector3d across(-u.y(), u.x(), 0.0);
  const Eigen::Matrix3d P = added.topLeftCorner<3, 3>();
  EXPECT_NEAR(std::sqrt(u.dot(P * u)), 0.025, 1e-12);
  EXPECT_NEAR(std::sqrt(across.dot(P * across)), 0.012, 1e-12);
  EXPECT_NEAR(std::sqrt(P(2, 2)), 0.012, 1e-12);
  EXPECT_NEAR(u.dot(P * across), 0.0, 1e-15);
  EXPECT_NEAR(std::sqrt(added(3, 3)), 2.6e-3, 1e-12);
  EXPECT_NEAR(added(0, 3), 0.0, 1e-18);
  // Twice the distance, twice the standard deviation.
  const Eigen::Matrix4d twice =
      FrameSwitchCovariance(FilterCovariance(), 2.0 * p_old_new_m, o) - FilterCovariance();
  EXPECT_NEAR(std::sqrt(u.dot(twice.topLeftCorner<3, 3>() * u)), 0.05, 1e-12);
}

TEST(FrameSwitchNoiseTest, NoDisplacementAddsNothing) {
  const Eigen::Matrix4d C =
      FrameSwitchCovariance(FilterCovariance(), Eigen::Vector3d::Zero(), FrameSwitchNoiseOptions{});
  EXPECT_TRUE(C.isApprox(FilterCovariance(), 1e-15));
}

TEST(FrameSwitchNoiseTest, ValidateNamesTheBadKey) {
  FrameSwitchNoiseOptions o;
  o.along_sigma_per_m = -0.1;
  try {
    o.Validate();
    FAIL() << "a negative error per metre was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("along_sigma_per_m"), std::string::npos) << e.what();
  }
  o = {};
  o.yaw_sigma_rad_per_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(o.Validate(), std::invalid_argument);
  o = {};
  o.filter_sigma_scale = 0.0;
  EXPECT_THROW(o.Validate(), std::invalid_argument);
}

TEST(FrameSwitchNoiseTest, LoadReadsTheKeysAndKeepsDefaultsForTheOthers) {
  const FrameSwitchNoiseOptions o = FrameSwitchNoiseOptions::Load(
      ConfigNode::LoadString("along_sigma_per_m: 0.004\nfilter_sigma_scale: 2\n", "test"));
  EXPECT_EQ(o.along_sigma_per_m, 0.004);
  EXPECT_EQ(o.filter_sigma_scale, 2.0);
  EXPECT_EQ(o.across_sigma_per_m, FrameSwitchNoiseOptions{}.across_sigma_per_m);
  EXPECT_THROW(
      FrameSwitchNoiseOptions::Load(ConfigNode::LoadString("across_sigma_per_m: -1\n", "test")),
      std::invalid_argument);
}

}  // namespace
}  // namespace rover::mapping
