#ifndef ROVER_MAPPING_TERRAIN_TRAVERSABILITY_GRID_H_
#define ROVER_MAPPING_TERRAIN_TRAVERSABILITY_GRID_H_

// The local obstacle map (thesis section 5.1.1): a robot-centred, rolling,
// gravity-aligned grid (5 cm) that low-pass filters the per-image step
// classifications over time. Each cell holds h_diff / (h_max + Delta_d)
// (> 1: untraversable); negative edges set their cells to a value above 1.
// When the rover moves, the grid scrolls by whole cells and what falls off
// the edge is forgotten, so memory is fixed and no allocation happens after
// construction.

#include <vector>

#include <Eigen/Core>

#include "mapping/terrain/negative_edge_detector.h"
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
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_TERRAIN_TRAVERSABILITY_GRID_H_
