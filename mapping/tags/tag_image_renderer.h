#ifndef ROVER_MAPPING_TAGS_TAG_IMAGE_RENDERER_H_
#define ROVER_MAPPING_TAGS_TAG_IMAGE_RENDERER_H_

// A rectified image of one printed tag at a known pose, for the detection
// error model's look-up table (as the thesis rendered its tags with a ray
// tracer and blurred them): the pattern mapped by the exact plane-to-image
// homography, supersampled and area-averaged (so that edges fall where the
// geometry puts them, to a small fraction of a pixel), then a Gaussian blur
// for the lens's defocus and optional sensor noise. It depends on nothing
// but the pattern and the rectified intrinsics, so host tools can use it.

#include <Eigen/Geometry>
#include <cstdint>

#include <opencv2/core.hpp>

#include "core/calib/stereo_rectifier.h"
#include "mapping/tags/tag_pattern.h"

namespace rover::mapping {

struct TagRenderOptions {
  int supersampling = 4;        ///< fine pixels per image pixel along each axis
  double blur_sigma_px = 0.6;   ///< defocus; 0: none
  uint8_t black_dn = 20;        ///< printed black, as imaged
  uint8_t white_dn = 220;       ///< printed white, as imaged
  uint8_t background_dn = 110;  ///< whatever lies around the tag
  double noise_sigma_dn = 0.0;  ///< Gaussian sensor noise; 0: none
  uint64_t noise_seed = 1;

  /// Throws std::invalid_argument "TagRenderOptions.<key>: ...".
  void Validate() const;
};

/// Renders `pattern` (its black square `tag_size_m` across) at T_camera_tag
/// (tag frame: x right, y down, z into the tag) into a `size` 8-bit image.
/// Throws std::invalid_argument for invalid options, a non-positive size or
/// a tag not in front of the camera.
cv::Mat RenderTagImage(const TagPattern& pattern, double tag_size_m,
                       const Eigen::Isometry3d& T_camera_tag,
                       const calib::RectifiedIntrinsics& camera, cv::Size size,
                       const TagRenderOptions& options = {});

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_TAGS_TAG_IMAGE_RENDERER_H_
