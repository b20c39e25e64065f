#ifndef ROVER_TESTS_MAPPING_TAGS_SYNTHETIC_TAG_IMAGE_H_
#define ROVER_TESTS_MAPPING_TAGS_SYNTHETIC_TAG_IMAGE_H_

// A rectified image of one tag36h11 marker at a known pose: the printed
// pattern (with its white ring) warped by the exact homography at 4x the
// resolution and area-averaged down, on a uniform grey background.

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "core/calib/stereo_rectifier.h"

namespace rover::mapping::testing {

cv::Mat RenderTag(int id, double tag_size_m, const Eigen::Isometry3d& T_camera_tag,
                  const calib::RectifiedIntrinsics& camera, int width = 752, int height = 480);

/// The rectified camera of the tests (752 x 480, 60 degrees across).
calib::RectifiedIntrinsics TestCamera();

/// A tag in front of the camera at `distance_m` along the optical axis
/// (shifted `lateral_m` to the right), its normal turned by `tilt_rad` about
/// the camera's y axis away from facing the camera head-on.
Eigen::Isometry3d TagAt(double distance_m, double tilt_rad, double lateral_m = 0.0);

}  // namespace rover::mapping::testing

#endif  // ROVER_TESTS_MAPPING_TAGS_SYNTHETIC_TAG_IMAGE_H_
