#include "mapping/tags/tag_border_fit.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "mapping/tags/tag_image_renderer.h"
#include "mapping/tags/tag_pattern.h"
#include "mapping/tags/tag_pose.h"
#include "tests/mapping/tags/synthetic_tag_image.h"

namespace rover::mapping {
namespace {

using testing::TagAt;
using testing::TestCamera;

constexpr double kTagSizeM = 0.16;
constexpr double kDeg = M_PI / 180.0;

cv::Mat Render(const Eigen::Isometry3d& T_camera_tag, double blur_px = 0.6) {
  TagRenderOptions options;
  options.blur_sigma_px = blur_px;
  options.noise_sigma_dn = 2.0;
  return RenderTagImage(MakeTagPattern("tag36h11", 7), kTagSizeM, T_camera_tag, TestCamera(),
                        cv::Size(752, 480), options);
}

std::array<Eigen::Vector2d, 4> TrueCorners(const Eigen::Isometry3d& T_camera_tag) {
  return ProjectTagCorners(T_camera_tag, kTagSizeM, TestCamera());
}

TEST(TagBorderFitTest, TheTrueCornersLieOnTheBorderAtAnyDistanceAndTilt) {
  for (const double distance_m : {0.5, 1.5, 4.0, 6.5}) {
    for (const double tilt_deg : {0.0, 35.0, -60.0, 75.0}) {
      const Eigen::Isometry3d T = TagAt(distance_m, tilt_deg * kDeg, 0.1);
      const TagBorderFit fit = FitTagBorder(Render(T), TrueCorners(T), {});
      ASSERT_TRUE(fit.measured) << distance_m << " m, " << tilt_deg << " deg";
      // Well inside the detector's default bound (0.75 px), even at 75 deg
      // and 4 m, where a bit across the long sides is under a pixel.
      EXPECT_LT(fit.worst_offset_px, 0.4) << distance_m << " m, " << tilt_deg << " deg";
      for (const double missing : fit.missing_fraction) EXPECT_LE(missing, 0.4);
    }
  }
}

TEST(TagBorderFitTest, AMisplacedCornerIsFoundWithItsOffset) {
  const Eigen::Isometry3d T = TagAt(2.0, 30.0 * kDeg, -0.2);
  const cv::Mat image = Render(T);
  for (std::size_t corner = 0; corner < 4; ++corner) {
    for (const double shift_px : {1.0, 2.5}) {
      std::array<Eigen::Vector2d, 4> corners = TrueCorners(T);
      // Away from the tag's centre, along the diagonal: off both sides.
      const Eigen::Vector2d centre = 0.25 * (corners[0] + corners[1] + corners[2] + corners[3]);
      corners[corner] += shift_px * (corners[corner] - centre).normalized();
      const TagBorderFit fit = FitTagBorder(image, corners, {});
      ASSERT_TRUE(fit.measured);
      EXPECT_EQ(fit.worst_corner, static_cast<int>(corner)) << shift_px << " px";
      EXPECT_NEAR(fit.worst_offset_px, shift_px, 0.3 * shift_px) << "corner " << corner;
      // The corner across from it keeps both its sides.
      EXPECT_LT(fit.corner_offsets_px[(corner + 2) % 4], 0.3);
    }
  }
}

TEST(TagBorderFitTest, AReversedBorderIsReadWithItsPolarity) {
  const Eigen::Isometry3d T = TagAt(1.2, -20.0 * kDeg);
  cv::Mat inverted;
  cv::bitwise_not(Render(T), inverted);
  std::array<Eigen::Vector2d, 4> corners = TrueCorners(T);
  corners[1].x() += 1.5;
  const TagBorderFit reversed = FitTagBorder(inverted, corners, {8, true});
  ASSERT_TRUE(reversed.measured);
  EXPECT_EQ(reversed.worst_corner, 1);
  EXPECT_GT(reversed.worst_offset_px, 1.0);
  // Read with the wrong polarity, the true corners do not fit.
  const TagBorderFit wrong = FitTagBorder(inverted, TrueCorners(T), {8, false});
  ASSERT_TRUE(wrong.measured);
  EXPECT_GT(wrong.worst_offset_px, 0.75);
}

TEST(TagBorderFitTest, NothingIsMeasuredWhereTheProfilesLeaveTheImage) {
  // The tag's left side 1 px from the image's edge: its profiles reach out.
  const calib::RectifiedIntrinsics camera = TestCamera();
  const double distance_m = 1.0;
  const double left_edge_m = (1.0 - camera.cx) / camera.fx * distance_m;
  const Eigen::Isometry3d T = TagAt(distance_m, 0.0, left_edge_m + kTagSizeM / 2);
  EXPECT_FALSE(FitTagBorder(Render(T), TrueCorners(T), {}).measured);
  // A degenerate quad and an image of another type neither.
  const std::array<Eigen::Vector2d, 4> point{Eigen::Vector2d(100, 100), Eigen::Vector2d(100, 100),
                                             Eigen::Vector2d(101, 100), Eigen::Vector2d(100, 101)};
  EXPECT_FALSE(FitTagBorder(Render(T), point, {}).measured);
  EXPECT_FALSE(
      FitTagBorder(cv::Mat(480, 752, CV_32FC1), TrueCorners(TagAt(1.0, 0.0)), {}).measured);
}

}  // namespace
}  // namespace rover::mapping
