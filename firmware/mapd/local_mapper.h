#ifndef ROVER_FIRMWARE_MAPD_LOCAL_MAPPER_H_
#define ROVER_FIRMWARE_MAPD_LOCAL_MAPPER_H_

// mapd's per-image pipeline (thesis chapter 5): rectify the raw pair, dense
// disparity (SGBM), depth with the stereo error model, obstacle
// classification on the single image before aggregation (negative edges and
// error-adaptive steps), the rolling traversability grid, and finally the
// points with their obstacle flags into the current submap.

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "core/calib/stereo_rectifier.h"
#include "mapping/depth/depth_image.h"
#include "mapping/depth/disparity_estimator.h"
#include "mapping/depth/stereo_error_model.h"
#include "mapping/submap/submap.h"
#include "mapping/terrain/height_map.h"
#include "mapping/terrain/negative_edge_detector.h"
#include "mapping/terrain/obstacle_cells.h"
#include "mapping/terrain/step_classifier.h"
#include "mapping/terrain/traversability_grid.h"

namespace rover::mapd {

struct LocalMapperOptions {
  mapping::DisparityOptions disparity;
  mapping::DepthImageOptions depth;
  /// Matching error of one image coordinate (thesis: 0.5 px), for sigma_z.
  double pixel_error_px = 0.5;
  mapping::HeightMapOptions height_map;
  mapping::StepClassifierOptions steps;
  mapping::NegativeEdgeOptions negative_edges;
  mapping::TraversabilityGridOptions traversability;
  /// Whole obstacles from the step grid (closing, raised regions).
  mapping::ObstacleCellOptions obstacle_cells;
  /// A point is flagged once this many images (this one included) have
  /// classified a cell of its obstacle as one (TraversabilityGrid::
  /// KeepConfirmed). Wrong stereo matches at the far end of the range make
  /// steps that the next pair, seen from 15 cm further on, does not repeat;
  /// a rock stays. 1 flags on the first sight. Negative edges are flagged
  /// at once.
  int min_obstacle_images = 2;

  /// Throws std::invalid_argument naming the component and key.
  void Validate() const;
};

/// What one image contributed.
struct MappedImage {
  mapping::DepthImageCounts depth;
  int obstacle_points = 0;  ///< valid points flagged as obstacles
  int negative_edges = 0;
  double disparity_ms = 0.0;
  double classification_ms = 0.0;
  double insertion_ms = 0.0;
};

class LocalMapper {
 public:
  /// Rectification from the two cameras' calibration. Throws
  /// std::invalid_argument if it is unusable or the options are invalid.
  LocalMapper(const LocalMapperOptions& options, const calib::CameraModel& cam0,
              const calib::CameraModel& cam1);

  /// Maps one raw mono8 pair taken at body pose `T_local_body` into
  /// `submap` (which lives in the same local frame). Throws
  /// std::invalid_argument if the images do not match the calibration.
  MappedImage Process(const cv::Mat& raw0, const cv::Mat& raw1,
                      const Eigen::Isometry3d& T_local_body, mapping::Submap* submap);

  /// The robot-centred traversability grid, in the current local frame.
  const mapping::TraversabilityGrid& traversability() const { return grid_; }
  /// Starts the grid afresh (after a frame switch its cells are in the old
  /// frame).
  void ResetTraversability();
  /// Pose of the rectified left camera on the body.
  const Eigen::Isometry3d& T_body_cam() const { return T_body_cam_; }
  /// The rectified left camera's pinhole and image size.
  const calib::RectifiedIntrinsics& rectified_intrinsics() const { return rectifier_.intrinsics(); }
  cv::Size rectified_size() const { return rectifier_.image_size(); }
  /// The latest rectified left image (empty before the first Process).
  const cv::Mat& rectified_left() const { return rect0_; }
  /// The latest depth image (for tests and tools).
  const mapping::DepthImage* last_depth() const { return has_depth_ ? &depth_ : nullptr; }
  /// The latest image's obstacle flags per pixel (row-major, 1: obstacle).
  const std::vector<uint8_t>& last_obstacle_mask() const { return obstacle_mask_; }

 private:
  /// Per-pixel obstacle flags of the valid points: on a confirmed obstacle
  /// cell of this image, or at a negative edge.
  int MarkObstacles(const std::vector<mapping::NegativeEdge>& edges,
                    const Eigen::Isometry3d& T_local_cam);

  LocalMapperOptions options_;
  calib::StereoRectifier rectifier_;
  mapping::RectifiedStereo stereo_;
  mapping::StereoErrorModel error_model_;
  mapping::DisparityEstimator disparity_;
  mapping::StepClassifier steps_;
  mapping::NegativeEdgeDetector edges_;
  mapping::ObstacleCellMarker obstacle_marker_;
  mapping::TraversabilityGrid grid_;
  Eigen::Isometry3d T_body_cam_ = Eigen::Isometry3d::Identity();
  cv::Mat rect0_, rect1_, disparity_q4_;
  mapping::DepthImage depth_;
  bool has_depth_ = false;
  std::vector<uint8_t> obstacle_mask_;
  mapping::ObstacleCells obstacle_cells_;  ///< the latest image's
};

}  // namespace rover::mapd

#endif  // ROVER_FIRMWARE_MAPD_LOCAL_MAPPER_H_
