#ifndef ROVER_MAPPING_TERRAIN_OBSTACLE_CELLS_H_
#define ROVER_MAPPING_TERRAIN_OBSTACLE_CELLS_H_

// From one image's step classification to its obstacle cells: whole
// obstacles rather than their edges.
//
// The step test flags a cell where its window spans a height difference
// above the threshold, i.e. the flanks of a rock. The rock's top is
// level within every window that lies on it, so a rock wider than two
// windows keeps an unflagged top inside the ring its flanks make, although
// the rover can no more drive there than over the flanks. Two steps fill it:
//  1. Closing (dilate, then erode) the step obstacles with a disc of
//     `closing_radius_m` joins a ring's gaps and fills small tops.
//  2. Raised regions: a connected area of known, unflagged cells (joined
//     across single unknown cells, which sparse sampling leaves) that is
//     bounded only by obstacle cells (and unknown cells: what the rock
//     hides, what is out of view) and lies on the upper side of every one
//     of those bounding steps is the top of what they border, and is
//     flagged whole. Upper side: nearer the step's top than its foot (the
//     highest and lowest cells of its window) and above the foot by more
//     than the step's own threshold (h_max plus the stereo error). Ground
//     between two rocks sits at their feet, so it stays free; the plain
//     above a crater's scarp is bounded by much more than the scarp, so it
//     stays free too. Areas wider than `max_raised_region_m` are terraces
//     rather than boulders and stay free.

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "mapping/terrain/height_map.h"
#include "mapping/terrain/step_classifier.h"

namespace rover::mapping {

struct ObstacleCellOptions {
  /// Radius of the closing disc; 0 disables it. 0.25 m: a rock top up to
  /// half a metre across, between flanks that the 0.3 m step window flags.
  double closing_radius_m = 0.25;
  /// Flag raised regions (see the file comment).
  bool fill_raised_regions = true;
  /// Largest raised region flagged whole (bounding box side). The largest
  /// boulders are about 3 m across (the simulator's reach 2.9 m).
  double max_raised_region_m = 3.0;
  /// Throws std::invalid_argument "ObstacleCellOptions.<key>: ...".
  void Validate() const;
};

/// One image's obstacle cells, on the step grid's cells.
struct ObstacleCells {
  int cols = 0;
  int rows = 0;
  double resolution_m = 0.05;
  Eigen::Vector2d origin_xy = Eigen::Vector2d::Zero();
  /// CV_8U, rows x cols, 255 where an obstacle is.
  cv::Mat mask;
  int raised_regions = 0;  ///< raised regions flagged whole

  bool Obstacle(int ix, int iy) const { return mask.at<uint8_t>(iy, ix) != 0; }
  /// Cell of a gravity-frame point; false outside the grid.
  bool CellOf(const Eigen::Vector3f& p, int* ix, int* iy) const;
};

class ObstacleCellMarker {
 public:
  /// `steps`: the step classifier's options (h_max, and its window, where
  /// a bounding step's foot is looked for). Throws std::invalid_argument
  /// for invalid options.
  ObstacleCellMarker(const ObstacleCellOptions& options, const StepClassifierOptions& steps);

  /// Obstacle cells of `steps` (classified on `map`); reuses `out`'s
  /// buffers.
  void Mark(const StepGrid& steps, const HeightMap& map, ObstacleCells* out);

 private:
  void FillRaisedRegions(const StepGrid& steps, const HeightMap& map, ObstacleCells* out);

  ObstacleCellOptions options_;
  StepClassifierOptions steps_;
  cv::Mat disc_;
  // Scratch, kept between images.
  cv::Mat heights_low_, heights_high_, foot_, top_, free_, labels_, stats_, centroids_;
  std::vector<uint8_t> bounded_above_;
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_TERRAIN_OBSTACLE_CELLS_H_
