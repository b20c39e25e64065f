#ifndef ROVER_MAPPING_TERRAIN_TRAVERSABILITY_GRID_H_
#define ROVER_MAPPING_TERRAIN_TRAVERSABILITY_GRID_H_

// The local obstacle map (thesis section 5.1.1): a robot-centred, rolling,
// gravity-aligned grid (5 cm) that low-pass filters the per-image step
// classifications over time. Each cell holds h_diff / (h_max + Delta_d)
// (> 1: untraversable); negative edges set their cells to a value above 1.
// When the rover moves, the grid scrolls by whole cells and what falls off
// the edge is forgotten, so memory is fixed and no allocation happens after
// construction. Each cell also counts the images whose obstacle cells
// (ObstacleCells: whole obstacles) included it, so that an obstacle can be
// confirmed by another look before the map takes it: a wrong stereo match
// rarely repeats from the next viewpoint, a rock does. Confirmation is per
// obstacle (a connected group of obstacle cells), not per cell: the far
// half of a rock's top, seen at a grazing angle, comes and goes from image
// to image while its flanks stay.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "mapping/terrain/negative_edge_detector.h"
#include "mapping/terrain/obstacle_cells.h"
#include "mapping/terrain/step_classifier.h"

namespace rover::mapping {

struct TraversabilityGridOptions {
  double resolution_m = 0.05;
  double half_extent_m = 5.0;  ///< the grid spans +-this around the rover
  /// Weight of a new observation in the exponential low-pass filter.
  double alpha = 0.3;
  /// Value written for a negative edge (untraversable).
  float negative_edge_value = 2.0f;

  /// Throws std::invalid_argument "TraversabilityGridOptions.<key>: ...".
  void Validate() const;
};

class TraversabilityGrid {
 public:
  explicit TraversabilityGrid(const TraversabilityGridOptions& options);

  /// Scrolls the grid so that it is centred on `rover_xy` (gravity frame).
  void Recentre(const Eigen::Vector2d& rover_xy);
  /// Folds one image's step classification and negative edges in.
  void Add(const StepGrid& steps, const std::vector<NegativeEdge>& edges);
  /// Counts one image's obstacle cells (saturating at 255 images).
  void CountObstacles(const ObstacleCells& cells);
  /// Images whose obstacle cells included the cell at a gravity-frame
  /// point; 0 if none or outside the grid.
  int ObstacleImages(const Eigen::Vector2d& xy) const;
  /// Clears the obstacles of `cells` (8-connected groups of obstacle cells)
  /// of which no cell has been counted in `min_images` images yet. Call
  /// after CountObstacles(*cells).
  void KeepConfirmed(int min_images, ObstacleCells* cells);

  int cells_per_side() const { return n_; }
  double resolution_m() const { return options_.resolution_m; }
  /// Lower corner of cell (0, 0), gravity frame.
  Eigen::Vector2d origin_xy() const;
  /// Filtered value at a gravity-frame point; negative if unknown or outside.
  float ValueAt(const Eigen::Vector2d& xy) const;
  /// Filtered value of cell (ix, iy), negative if unknown.
  float value(int ix, int iy) const {
    return values_[static_cast<std::size_t>(iy) * static_cast<std::size_t>(n_) +
                   static_cast<std::size_t>(ix)];
  }

 private:
  void Blend(long cx, long cy, float observation);
  bool Local(long cx, long cy, int* ix, int* iy) const;

  TraversabilityGridOptions options_;
  int n_ = 0;
  long origin_cx_ = 0;  ///< global cell index of local cell (0, 0)
  long origin_cy_ = 0;
  std::vector<float> values_;
  std::vector<float> scratch_;
  std::vector<uint8_t> obstacle_images_;
  std::vector<uint8_t> obstacle_scratch_;
  cv::Mat labels_;
  std::vector<uint8_t> confirmed_;
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_TERRAIN_TRAVERSABILITY_GRID_H_
