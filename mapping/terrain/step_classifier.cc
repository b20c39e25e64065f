#include "mapping/terrain/step_classifier.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace rover::mapping {

void StepClassifierOptions::Validate() const {
  if (!(std::isfinite(h_max_m) && h_max_m > 0.0)) {
    throw std::invalid_argument("StepClassifierOptions.h_max_m: expected > 0, found " +
                                std::to_string(h_max_m));
  }
  if (!(std::isfinite(sigma_factor) && sigma_factor >= 0.0)) {
    throw std::invalid_argument("StepClassifierOptions.sigma_factor: expected >= 0, found " +
                                std::to_string(sigma_factor));
  }
  if (window_cells < 2 || window_cells > 16) {
    throw std::invalid_argument("StepClassifierOptions.window_cells: expected 2..16, found " +
                                std::to_string(window_cells));
  }
}

StepClassifier::StepClassifier(const StepClassifierOptions& options, const StereoErrorModel& model)
    : options_(options), model_(model) {
  options_.Validate();
}

StepGrid StepClassifier::Classify(const HeightMap& map,
                                  const Eigen::Isometry3d& T_gravity_cam) const {
  StepGrid grid;
  grid.cols = map.cols();
  grid.rows = map.rows();
  grid.resolution_m = map.resolution_m();
  grid.origin_xy = map.origin_xy();
  grid.traversability.assign(
      static_cast<std::size_t>(grid.cols) * static_cast<std::size_t>(grid.rows), -1.0f);
  const Eigen::Isometry3d T_cam_gravity = T_gravity_cam.inverse();
  const Eigen::Vector3d up_cam = T_cam_gravity.linear() * Eigen::Vector3d::UnitZ();
  const int lo = options_.window_cells / 2;  // window: [i - lo, i - lo + window)
  for (int iy = 0; iy < map.rows(); ++iy) {
    for (int ix = 0; ix < map.cols(); ++ix) {
      if (!map.Has(ix, iy)) continue;
      int min_x = -1, min_y = -1, max_x = -1, max_y = -1;
      int cells = 0;
      const int x_end = std::min(map.cols(), ix - lo + options_.window_cells);
      const int y_end = std::min(map.rows(), iy - lo + options_.window_cells);
      for (int wy = std::max(0, iy - lo); wy < y_end; ++wy) {
        for (int wx = std::max(0, ix - lo); wx < x_end; ++wx) {
          if (!map.Has(wx, wy)) continue;
          ++cells;
          if (min_x < 0 || map.height(wx, wy) < map.height(min_x, min_y)) {
            min_x = wx;
            min_y = wy;
          }
          if (max_x < 0 || map.height(wx, wy) > map.height(max_x, max_y)) {
            max_x = wx;
            max_y = wy;
          }
        }
      }
      if (cells < 2) continue;
      const double h_diff = map.height(max_x, max_y) - map.height(min_x, min_y);
      double threshold = options_.h_max_m;
      if (options_.error_adaptive && h_diff > 0.0) {
        const Eigen::Vector3d p = T_cam_gravity * map.CellPoint(max_x, max_y);
        const Eigen::Vector3d q = T_cam_gravity * map.CellPoint(min_x, min_y);
        if (p.z() > 0.0 && q.z() > 0.0) {
          const double sigma = options_.error_term == StepErrorTerm::kDistance
                                   ? model_.DistanceSigma(p, q)
                                   : model_.HeightDifferenceSigma(p, q, up_cam);
          threshold += options_.sigma_factor * sigma;
        }
      }
      grid.traversability[static_cast<std::size_t>(iy) * static_cast<std::size_t>(grid.cols) +
                          static_cast<std::size_t>(ix)] = static_cast<float>(h_diff / threshold);
    }
  }
  return grid;
}

}  // namespace rover::mapping
