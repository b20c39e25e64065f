#include "mapping/tags/tag_detector.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "mapping/tags/tag_image_renderer.h"
#include "mapping/tags/tag_pattern.h"
#include "mapping/tags/tag_pose.h"
#include "tests/mapping/tags/synthetic_tag_image.h"

namespace rover::mapping {
namespace {

using testing::RenderTag;
using testing::TagAt;
using testing::TestCamera;

constexpr double kTagSizeM = 0.16;

double MaxCornerErrorPx(const TagDetection& d, const Eigen::Isometry3d& T) {
  const auto truth = ProjectTagCorners(T, kTagSizeM, TestCamera());
  double worst = 0.0;
  for (std::size_t k = 0; k < 4; ++k) worst = std::max(worst, (d.corners_px[k] - truth[k]).norm());
  return worst;
}

TEST(TagDetectorTest, FindsTheTagWithItsCornersWhereTheyProject) {
  TagDetector detector(TagDetectorOptions{});
  for (const double tilt_deg : {0.0, 30.0, -50.0}) {
    const Eigen::Isometry3d T = TagAt(1.5, tilt_deg * M_PI / 180.0, 0.2);
    const cv::Mat image = RenderTag(42, kTagSizeM, T, TestCamera());
    std::vector<TagRefusal> refused;
    const std::vector<TagDetection> found = detector.Detect(image, &refused);
    ASSERT_EQ(found.size(), 1u) << "tilt " << tilt_deg;
    EXPECT_TRUE(refused.empty());
    EXPECT_EQ(found[0].family, "tag36h11");
    EXPECT_EQ(found[0].id, 42);
    EXPECT_EQ(found[0].hamming, 0);
    EXPECT_LT(MaxCornerErrorPx(found[0], T), 0.3) << "tilt " << tilt_deg;
  }
}

TEST(TagDetectorTest, ATagCutByTheImageBorderIsRefusedWithTheReason) {
  // Quads found at full resolution: decimated, a tag this close to the
  // border is mostly not found at all, which would leave the check untried.
  TagDetectorOptions options;
  options.quad_decimate = 1.0;
  TagDetector detector(options);
  // The tag slides out of the view on the left, 1 m away, a quarter pixel
  // at a time. Whatever is accepted has all four corners clear of the
  // border; while the code is still readable but a corner is within the
  // margin, the tag is refused as cut by the border.
  const calib::RectifiedIntrinsics camera = TestCamera();
  const double margin_px = TagDetectorOptions{}.border_margin_px;
  int cut = 0;
  for (int step = 0; step < 40; ++step) {
    const double corner_x_px = 6.0 - 0.25 * step;
    const double centre_x_m = (corner_x_px - camera.cx) / camera.fx + kTagSizeM / 2;
    const Eigen::Isometry3d T = TagAt(1.0, 0.0, centre_x_m);
    std::vector<TagRefusal> refused;
    const auto found = detector.Detect(RenderTag(3, kTagSizeM, T, camera), &refused);
    for (const TagDetection& d : found) {
      for (const Eigen::Vector2d& c : d.corners_px) EXPECT_GE(c.x(), margin_px) << corner_x_px;
    }
    for (const TagRefusal& r : refused) {
      EXPECT_EQ(r.id, 3);
      if (r.reason.find("image border") == std::string::npos) continue;
      ++cut;
      // Logged with where it was: the corner that the border cut.
      double min_x_px = 1e9;
      for (const Eigen::Vector2d& c : r.corners_px) min_x_px = std::min(min_x_px, c.x());
      EXPECT_NEAR(min_x_px, corner_x_px, 1.0);
    }
  }
  EXPECT_GT(cut, 0) << "no readable tag was ever refused as cut by the border";
}

// A tag on a shaded post face, 3 cm of dim margin to the face's edge, dark
// sky above and bright ground below the horizon behind it: the scene where
// the library's segmentation runs past the margin at a corner.
cv::Mat ShadedPostFace(const Eigen::Isometry3d& T, uint8_t ground_dn) {
  const calib::RectifiedIntrinsics camera = TestCamera();
  TagRenderOptions options;
  options.blur_sigma_px = 0.0;
  options.black_dn = 6;
  options.white_dn = 95;
  options.background_dn = 95;  // the face: the same paint as the margin
  cv::Mat image = RenderTagImage(MakeTagPattern("tag36h11", 15), kTagSizeM, T, camera,
                                 cv::Size(752, 480), options);
  const double half_face_m = 0.5 * (1.25 * kTagSizeM + 0.02);
  std::vector<cv::Point> face;
  for (const auto& [x, y] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
    const Eigen::Vector3d p = T * Eigen::Vector3d(x * half_face_m, y * half_face_m, 0.0);
    face.emplace_back(static_cast<int>(std::lround(camera.fx * p.x() / p.z() + camera.cx)),
                      static_cast<int>(std::lround(camera.fy * p.y() / p.z() + camera.cy)));
  }
  cv::Mat on_face = cv::Mat::zeros(image.size(), CV_8UC1);
  cv::fillConvexPoly(on_face, face, cv::Scalar(255));
  const Eigen::Vector3d centre = T.translation();
  const int horizon_row = static_cast<int>(camera.fy * centre.y() / centre.z() + camera.cy);
  for (int r = 0; r < image.rows; ++r) {
    for (int c = 0; c < image.cols; ++c) {
      if (on_face.at<uint8_t>(r, c) == 0)
        image.at<uint8_t>(r, c) = r < horizon_row ? 30 : ground_dn;
    }
  }
  cv::GaussianBlur(image, image, cv::Size(0, 0), 0.7);
  return image;
}

TEST(TagDetectorTest, ACornerRunOffTheBorderIsRefused) {
  TagDetectorOptions library_options;
  library_options.max_border_offset_px = 0.0;
  TagDetector library_only(library_options);
  TagDetector detector(TagDetectorOptions{});
  int run_off = 0;  // the library's corner more than 1 px off
  int clean = 0;    // all its corners within 0.5 px
  for (double tilt_deg = -50.0; tilt_deg <= 50.0; tilt_deg += 5.0) {
    for (const int ground_dn : {120, 150, 180}) {
      Eigen::Isometry3d T = TagAt(3.7, tilt_deg * M_PI / 180.0, 0.3);
      T.translation().y() = -0.9;  // high in the image, as a post's head seen from a rover
      const cv::Mat image = ShadedPostFace(T, static_cast<uint8_t>(ground_dn));
      const auto raw = library_only.Detect(image);
      if (raw.size() != 1) continue;
      const double library_error_px = MaxCornerErrorPx(raw[0], T);
      std::vector<TagRefusal> refused;
      const auto found = detector.Detect(image, &refused);
      const std::string where = std::to_string(tilt_deg) + " deg, ground " +
                                std::to_string(ground_dn) + ", library's corner error " +
                                std::to_string(library_error_px) + " px";
      for (const TagDetection& d : found) EXPECT_LE(MaxCornerErrorPx(d, T), 1.0) << where;
      if (library_error_px > 1.0) {
        ++run_off;
        ASSERT_EQ(refused.size(), 1u) << where;
        EXPECT_NE(refused[0].reason.find("off the tag's border"), std::string::npos)
            << refused[0].reason;
      } else if (library_error_px < 0.5) {
        ++clean;
        EXPECT_EQ(found.size(), 1u) << where;
      }
    }
  }
  // The scene does what the simulator's posts did, and the check keeps the
  // good detections.
  EXPECT_GE(run_off, 8);
  EXPECT_GE(clean, 20);
}

TEST(TagDetectorTest, ABlankImageHasNoDetection) {
  TagDetector detector(TagDetectorOptions{});
  const cv::Mat grey(480, 752, CV_8UC1, cv::Scalar(128));
  std::vector<TagRefusal> refused;
  EXPECT_TRUE(detector.Detect(grey, &refused).empty());
  EXPECT_TRUE(refused.empty());
}

TEST(TagDetectorTest, OptionsAndInputsAreCheckedWithClearMessages) {
  TagDetectorOptions o;
  o.families = {"tag36h11", "tag99x1"};
  try {
    TagDetector detector(o);
    FAIL() << "an unknown family was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'tag99x1'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("tagStandard41h12"), std::string::npos) << e.what();
  }
  o = TagDetectorOptions{};
  o.max_hamming = 3;  // more than it may correct
  EXPECT_THROW(o.Validate(), std::invalid_argument);
  o = TagDetectorOptions{};
  o.quad_decimate = 0.5;
  EXPECT_THROW(o.Validate(), std::invalid_argument);
  o = TagDetectorOptions{};
  o.families = {"tag25h9", "tagStandard41h12"};
  EXPECT_NO_THROW(TagDetector{o});

  TagDetector detector(TagDetectorOptions{});
  const cv::Mat colour(480, 752, CV_8UC3, cv::Scalar(0, 0, 0));
  EXPECT_THROW(detector.Detect(colour), std::invalid_argument);
  EXPECT_THROW(detector.Detect(cv::Mat()), std::invalid_argument);
}

TEST(TagPoseTest, RecoversThePoseAndKeepsTheMirroredSolution) {
  TagDetector detector(TagDetectorOptions{});
  const calib::RectifiedIntrinsics camera = TestCamera();
  for (const double tilt_deg : {-60.0, -35.0, 35.0, 60.0}) {
    const Eigen::Isometry3d T = TagAt(2.0, tilt_deg * M_PI / 180.0, -0.3);
    const auto found = detector.Detect(RenderTag(11, kTagSizeM, T, camera));
    ASSERT_EQ(found.size(), 1u);
    std::string error;
    const auto pose = EstimateTagPose(found[0].corners_px, kTagSizeM, camera, &error);
    ASSERT_TRUE(pose.has_value()) << error;
    const Eigen::Isometry3d& E = pose->best.T_camera_tag;
    EXPECT_LT((E.translation() - T.translation()).norm(), 0.01 * T.translation().norm())
        << "tilt " << tilt_deg;
    const double angle_deg =
        Eigen::AngleAxisd(E.linear().transpose() * T.linear()).angle() * 180.0 / M_PI;
    EXPECT_LT(angle_deg, 2.0) << "tilt " << tilt_deg;
    // The other solution is the mirrored tilt, and fits clearly worse when
    // the tag is this oblique.
    const double alt_deg =
        Eigen::AngleAxisd(pose->alternative.T_camera_tag.linear().transpose() * T.linear())
            .angle() *
        180.0 / M_PI;
    EXPECT_GT(alt_deg, 10.0) << "tilt " << tilt_deg;
    EXPECT_LT(pose->ambiguity_ratio, 0.5) << "tilt " << tilt_deg;
    EXPECT_NEAR(pose->distance_m, T.translation().norm(), 0.02);
  }
}

TEST(TagPoseTest, AHeadOnDistantTagIsAmbiguous) {
  // Small in the image and facing the camera: both solutions fit the
  // corners about equally well.
  const calib::RectifiedIntrinsics camera = TestCamera();
  const Eigen::Isometry3d T = TagAt(6.0, 5.0 * M_PI / 180.0);
  TagDetector detector(TagDetectorOptions{});
  const auto found = detector.Detect(RenderTag(5, kTagSizeM, T, camera));
  ASSERT_EQ(found.size(), 1u);
  std::string error;
  const auto pose = EstimateTagPose(found[0].corners_px, kTagSizeM, camera, &error);
  ASSERT_TRUE(pose.has_value()) << error;
  EXPECT_GT(pose->ambiguity_ratio, 0.3);
}

TEST(TagPoseTest, ExactCornersGiveTheExactPoseAndTiltSign) {
  const calib::RectifiedIntrinsics camera = TestCamera();
  for (const double tilt_deg : {-40.0, 25.0}) {
    const Eigen::Isometry3d T = TagAt(1.2, tilt_deg * M_PI / 180.0, 0.1);
    std::string error;
    const auto pose =
        EstimateTagPose(ProjectTagCorners(T, kTagSizeM, camera), kTagSizeM, camera, &error);
    ASSERT_TRUE(pose.has_value()) << error;
    EXPECT_LT((pose->best.T_camera_tag.matrix() - T.matrix()).cwiseAbs().maxCoeff(), 1e-6);
    EXPECT_LT(pose->best.reprojection_rmse_px, 1e-6);
    // Tilt: the angle from the line of sight to the tag's normal, positive
    // towards the image's right. Turning the tag by -a about the camera's y
    // swings its normal a to the right; the line of sight to a centre at
    // bearing b to the right leans b the other way.
    const double bearing = std::atan2(T.translation().x(), T.translation().z());
    EXPECT_NEAR(pose->tilt_rad, -tilt_deg * M_PI / 180.0 + bearing, 1e-6) << tilt_deg;
  }
}

TEST(TagPoseTest, BadInputIsRefusedWithTheReason) {
  const calib::RectifiedIntrinsics camera = TestCamera();
  auto corners = ProjectTagCorners(TagAt(1.0, 0.3), kTagSizeM, camera);
  std::string error;
  EXPECT_FALSE(EstimateTagPose(corners, 0.0, camera, &error).has_value());
  EXPECT_NE(error.find("tag size"), std::string::npos) << error;
  corners[2].x() = std::nan("");
  EXPECT_FALSE(EstimateTagPose(corners, kTagSizeM, camera, &error).has_value());
  EXPECT_NE(error.find("corner 2"), std::string::npos) << error;
  calib::RectifiedIntrinsics bad = camera;
  bad.fx = -1.0;
  EXPECT_FALSE(
      EstimateTagPose(ProjectTagCorners(TagAt(1.0, 0.3), kTagSizeM, camera), kTagSizeM, bad, &error)
          .has_value());
}

}  // namespace
}  // namespace rover::mapping
