#ifndef ROVER_MAPPING_TERRAIN_STEP_CLASSIFIER_H_
#define ROVER_MAPPING_TERRAIN_STEP_CLASSIFIER_H_

// Stereo error-adaptive step classification (thesis section 5.1.1, Figure
// 5.3): around every cell of a height map, the largest height difference
// h_diff within a small square window (3-6 cells) is compared with
//     h_max + Delta_d
// where h_max is the highest step the rover climbs and Delta_d the stereo
// error of the distance between the two cells that make h_diff (their
// centres at their mean heights, taken back into the camera frame; see
// StereoErrorModel::DistanceSigma). A cell is an obstacle if h_diff exceeds
// it; h_diff / (h_max + Delta_d) is its traversability value (> 1:
// untraversable), which the rolling traversability grid filters over time.
// Without Delta_d the rover would hallucinate obstacles farther away, where
// stereo heights are noisier.

#include <vector>

#include <Eigen/Geometry>

#include "mapping/depth/stereo_error_model.h"
#include "mapping/terrain/height_map.h"

namespace rover::mapping {

struct StepClassifierOptions {
  /// Highest step the wheels climb (the simulator's obstacle rule: 0.1 m).
  double h_max_m = 0.1;
  /// Window edge in cells: 6 cells = 0.3 m at 5 cm, the rover's wheel scale.
  int window_cells = 6;
  /// Leave Delta_d out (for comparison: what the thesis argues against).
  bool error_adaptive = true;
  /// The threshold is h_max + sigma_factor * Delta_d; the thesis adds
  /// Delta_d itself (1). With the height map's median filter taking out the
  /// lone spikes of wrong matches, 1 leaves no false steps on the
  /// simulator's level ground, and larger factors only lose far obstacles.
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
  /// h_diff / (h_max + Delta_d) per cell; negative where the cell is empty
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
