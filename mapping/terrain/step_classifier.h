#ifndef ROVER_MAPPING_TERRAIN_STEP_CLASSIFIER_H_
#define ROVER_MAPPING_TERRAIN_STEP_CLASSIFIER_H_

// Stereo error-adaptive step classification (thesis section 5.1.1, Figure
// 5.3): around every cell of a height map, the largest height difference
// h_diff within a small square window (3-6 cells) is compared with
//     h_max + Delta
// where h_max is the highest step the rover climbs and Delta the stereo
// error of h_diff between the two cells that make it (their centres at their
// mean heights, taken back into the camera frame). A cell is an obstacle if
// h_diff exceeds it; h_diff / (h_max + Delta) is its traversability value
// (> 1: untraversable), which the rolling traversability grid filters over
// time. Without Delta the rover would hallucinate obstacles farther away,
// where stereo heights are noisier.
//
// The thesis takes for Delta the error Delta_d of the distance between the
// two points (its eq. 5.4). That is the error of h_diff only when the two
// points lie one above the other; for two cells side by side across the
// line of sight, Delta_d is nearly blind to the depth error that moves
// both heights (see StereoErrorModel::HeightDifferenceSigma), and level
// ground at 3-4 m, where each cell's height is off by about 5 cm on the
// simulator's head, comes out as steps. So the default is the error of the
// height difference itself; `error_term` keeps the thesis's literal choice
// for comparison.

#include <vector>

#include <Eigen/Geometry>

#include "mapping/depth/stereo_error_model.h"
#include "mapping/terrain/height_map.h"

namespace rover::mapping {

/// Which stereo error makes the adaptive part of the threshold.
enum class StepErrorTerm {
  kHeightDifference,  ///< error of h_diff itself (the vertical part of both points' errors)
  kDistance,          ///< the thesis's Delta_d (eq. 5.4), the error of |p - q|
};

struct StepClassifierOptions {
  /// Highest step the wheels climb (the simulator's obstacle rule: 0.1 m).
  double h_max_m = 0.1;
  /// Window edge in cells: 6 cells = 0.3 m at 5 cm, the rover's wheel scale.
  int window_cells = 6;
  /// Leave the stereo error out (for comparison: what the thesis argues
  /// against).
  bool error_adaptive = true;
  StepErrorTerm error_term = StepErrorTerm::kHeightDifference;
  /// The threshold is h_max + sigma_factor * Delta; the thesis adds the
  /// error itself (1).
  double sigma_factor = 1.0;

  /// Throws std::invalid_argument "StepClassifierOptions.<key>: ...".
  void Validate() const;
};

/// The classification of one height map (same grid).
struct StepGrid {
  int cols = 0;
  int rows = 0;
  double resolution_m = 0.05;
  Eigen::Vector2d origin_xy = Eigen::Vector2d::Zero();
  /// h_diff / (h_max + Delta) per cell; negative where the cell is empty
  /// or has no neighbour with data.
  std::vector<float> traversability;

  float at(int ix, int iy) const {
    return traversability[static_cast<std::size_t>(iy) * static_cast<std::size_t>(cols) +
                          static_cast<std::size_t>(ix)];
  }
  bool Known(int ix, int iy) const { return at(ix, iy) >= 0.0f; }
  bool Obstacle(int ix, int iy) const { return at(ix, iy) > 1.0f; }
};

class StepClassifier {
 public:
  /// `model` must outlive the classifier.
  StepClassifier(const StepClassifierOptions& options, const StereoErrorModel& model);

  StepGrid Classify(const HeightMap& map, const Eigen::Isometry3d& T_gravity_cam) const;

 private:
  StepClassifierOptions options_;
  const StereoErrorModel& model_;
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_TERRAIN_STEP_CLASSIFIER_H_
