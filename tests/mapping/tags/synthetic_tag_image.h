#ifndef ROVER_TESTS_MAPPING_TAGS_SYNTHETIC_TAG_IMAGE_H_
#define ROVER_TESTS_MAPPING_TAGS_SYNTHETIC_TAG_IMAGE_H_

// The tags tests' camera and poses, and one tag36h11 marker rendered at a
// known pose with mapping's tag renderer (sharp: no blur, no noise).

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "core/calib/stereo_rectifier.h"

namespace rover::mapping::testing {

cv::Mat RenderTag(int id, double tag_size_m, const Eigen::Isometry3d& T_camera_tag,
                  const calib::RectifiedIntrinsics& camera);

/// The rectified camera of the tests (752 x 480, 60 degrees across).
calib::RectifiedIntrinsics TestCamera();

/// A tag in front of the camera at `distance_m` along the optical axis
/// (shifted `lateral_m` to the right), turned by `tilt_rad` about the
/// camera's y axis from facing the camera head-on.
Eigen::Isometry3d TagAt(double distance_m, double tilt_rad, double lateral_m = 0.0);

}  // namespace rover::mapping::testing

#endif  // ROVER_TESTS_MAPPING_TAGS_SYNTHETIC_TAG_IMAGE_H_
