#ifndef ROVER_MAPPING_TAGS_TAG_ERROR_TABLE_H_
#define ROVER_MAPPING_TAGS_TAG_ERROR_TABLE_H_

// The offline step of the thesis's detection error model (6.2.3): the
// maximum tag pose errors over a grid of distance d and tilt Phi, for one
// camera (rectified resolution and intrinsics), tag family and tag size. A
// cell holds, per degree of freedom (TagPoseErrors), the largest error of
// the detections of a tag rendered at that pose, its corners perturbed by
// +-delta_px as in the online step. Post-processing as the thesis: a 3x3
// median filter against untypical cells, then cells where the tag was not
// detected filled along each distance row from the valid region's border,
// and the rest of each tilt column with the maximum of the last 10 % of its
// valid values. Lookups interpolate bilinearly and clamp to the grid.
//
// File: YAML (format rover_tag_error_table, version 1) with the camera, the
// tag, the grid and the cells; Load refuses a table made for another camera
// or tag (CheckMatches).

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/calib/stereo_rectifier.h"
#include "mapping/tags/tag_image_renderer.h"
#include "mapping/tags/tag_pose_errors.h"

namespace rover::mapping {

struct TagErrorTableSpec {
  calib::RectifiedIntrinsics camera;
  cv::Size image_size{752, 480};
  std::string family = "tag36h11";
  int tag_id = 0;  ///< the id rendered (the pattern hardly matters; the size does)
  double tag_size_m = 0.16;
  double corner_delta_px = 0.3;  ///< the calibration's pixel error
  double min_distance_m = 0.2;
  double max_distance_m = 7.0;
  int distance_steps = 60;
  double max_tilt_rad = 89.0 * 3.14159265358979323846 / 180.0;  ///< grid over [-max, max]
  int tilt_steps = 60;
  TagRenderOptions render{};

  /// Throws std::invalid_argument "TagErrorTableSpec.<key>: ...".
  void Validate() const;
};

/// The table's file name for `family` and `tag_size_m`:
/// "tag_errors_<family>_<size in mm>mm.yaml". rover-tags writes it beside the
/// board's calibration.
std::string TagErrorTableFileName(const std::string& family, double tag_size_m);

class TagErrorTable {
 public:
  /// An empty table (every cell undetected) on `spec`'s grid.
  explicit TagErrorTable(const TagErrorTableSpec& spec);

  /// Renders, detects and perturbs every cell (one row of distances at a
  /// time; `progress(done, total)` after each cell), then post-processes.
  static TagErrorTable Build(const TagErrorTableSpec& spec,
                             const std::function<void(std::size_t, std::size_t)>& progress = {});

  /// Reads a table written by Save. Throws std::runtime_error naming the
  /// file, the line and what was expected.
  static TagErrorTable Load(const std::string& path);
  /// Writes the table; throws std::runtime_error naming the path.
  void Save(const std::string& path) const;

  /// Throws std::invalid_argument saying what differs if this table was
  /// not made for `camera` at `image_size` (focal lengths and centre within
  /// 0.5 px), `family` and `tag_size_m` (within 0.1 mm).
  void CheckMatches(const calib::RectifiedIntrinsics& camera, cv::Size image_size,
                    const std::string& family, double tag_size_m) const;

  /// Bilinear in (distance, tilt), clamped to the grid.
  TagPoseErrors Lookup(double distance_m, double tilt_rad) const;

  const TagErrorTableSpec& spec() const { return spec_; }
  double Distance(int i) const;
  double Tilt(int j) const;
  /// Cell (distance i, tilt j); NaN where not detected (before filling).
  const TagPoseErrors& At(int i, int j) const;
  TagPoseErrors& At(int i, int j);
  /// Cells where the rendered tag was detected (before filling).
  std::size_t detected_cells() const { return detected_cells_; }

  /// The thesis's post-processing (median filter, then fill); Build calls it.
  void PostProcess();

 private:
  TagErrorTableSpec spec_;
  std::vector<TagPoseErrors> cells_;  ///< row-major: distance i, tilt j
  std::size_t detected_cells_ = 0;
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_TAGS_TAG_ERROR_TABLE_H_
