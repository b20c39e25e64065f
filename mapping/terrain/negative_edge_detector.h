#ifndef ROVER_MAPPING_TERRAIN_NEGATIVE_EDGE_DETECTOR_H_
#define ROVER_MAPPING_TERRAIN_NEGATIVE_EDGE_DETECTOR_H_

// Negative edges (cliffs, crater scarps) straight in the depth image, before
// anything is aggregated (thesis section 5.1.1): the information that the
// ground beyond an edge is far below, or out of stereo range altogether, is
// lost in a height map.
//
// Each column is walked top to bottom and every pixel compared with its
// upper neighbour. Where their depths differ by more than `depth_jump_m`
// (0.2 m on the thesis's rovers; plus the stereo error of the difference,
// see the option), the upper pixel's point p lies beyond the
// edge and the lower pixel's point q on its near side. In the
// gravity-aligned frame the steepest slope the unseen ground between them
// must have somewhere is at least
//     s_min = (q_z - p_z) / |(q_x - p_x, q_y - p_y)|      (thesis eq. 5.1)
// and the near point q is flagged when s_min exceeds the steepest slope the
// rover may drive. An upper neighbour that is infinitely far (zero
// disparity) is the limiting case, the ground beyond out of range: it flags
// q when ground continuing level with q would have crossed that ray within
// `out_of_range_distance_m` (well inside stereo range), so the ground must
// drop instead. Level ground fading out at the end of stereo range is not
// flagged that way. (Our reading: the thesis keeps such pixels distinct for
// this case but does not spell it out.) Assumes small roll, as the thesis
// does.

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "mapping/depth/depth_image.h"

namespace rover::mapping {

struct NegativeEdgeOptions {
  double depth_jump_m = 0.2;
  /// Add the stereo error of the two depths' difference (sqrt(sigma_z,p^2 +
  /// sigma_z,q^2)) to `depth_jump_m`, as the step test adds its error: the
  /// thesis's 0.2 m is many sigma at 2 m on its f = 1080 px heads (sigma_z
  /// 3 cm), but barely more than one on the simulator's f = 422 px head
  /// (7 cm), where a wrong match along a ray steeper than max_slope_deg
  /// would pass for an edge. A real drop hides metres of ground.
  bool error_adaptive = true;
  /// Steepest traversable slope (the simulator's obstacle rule uses 25 deg).
  double max_slope_deg = 25.0;
  /// Flag infinitely far upper neighbours (see the file comment).
  bool flag_out_of_range = true;
  /// Level ground would be seen in range up to this distance along a ray.
  double out_of_range_distance_m = 6.0;

  /// Throws std::invalid_argument "NegativeEdgeOptions.<key>: ...".
  void Validate() const;
};

/// One flagged edge: the near-side point and the slope that condemned it.
struct NegativeEdge {
  int u = 0;
  int v = 0;
  Eigen::Vector3d q_gravity = Eigen::Vector3d::Zero();  ///< near side, gravity frame
  double min_slope = 0.0;  ///< s_min; +infinity for an out-of-range far side
};

class NegativeEdgeDetector {
 public:
  explicit NegativeEdgeDetector(const NegativeEdgeOptions& options);

  /// Edges of one depth image. `T_gravity_cam` maps camera points into the
  /// gravity-aligned frame (z up) the slopes are measured in.
  std::vector<NegativeEdge> Detect(const DepthImage& depth,
                                   const Eigen::Isometry3d& T_gravity_cam) const;

 private:
  NegativeEdgeOptions options_;
  double max_slope_;  ///< tan(max_slope_deg)
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_TERRAIN_NEGATIVE_EDGE_DETECTOR_H_
