#ifndef ROVER_HIL_SIM_EXPERIMENTS_TAG_EVALUATION_H_
#define ROVER_HIL_SIM_EXPERIMENTS_TAG_EVALUATION_H_

// mapd's logged tag detections against the simulator's truth: for every
// accepted detection of a tag on a landmark post, the true pose of the tag
// in the rectified left camera at the image's capture time, the error of
// the logged pose, and its NEES under the logged covariance (over [dt (m,
// camera); dtheta (rad, tag, right)], as the error model states it).

#include <cstdint>
#include <functional>
#include <limits>
#include <ostream>
#include <vector>

#include <Eigen/Geometry>

#include "core/log/msgs/rover_msgs.h"
#include "core/time/time.h"
#include "hil/sim/world/world.h"

namespace rover::sim::experiments {

/// An accepted detection whose pose took the wrong solution of the planar
/// ambiguity (rotation more than 20 deg off), as logged.
struct WrongTagSolution {
  Time stamp;
  int id = 0;
  double distance_m = 0.0;
  double tilt_deg = 0.0;
  double ambiguity_ratio = 0.0;
  uint32_t flipped = 0;  ///< of the 256 perturbed poses
  double rotation_error_deg = 0.0;
  /// Under the logged rotation covariance; beyond 7.81 the detection claims
  /// the wrong rotation.
  double rotation_nees = 0.0;
};

struct TagScore {
  uint64_t decoded = 0;        ///< logged observations (accepted or refused)
  uint64_t accepted = 0;       ///< of those, accepted
  uint64_t scored = 0;         ///< accepted landmark tags with a true pose
  uint64_t nees_in_bound = 0;  ///< NEES within the chi^2(6) 95 % bound (12.59)
  double nees_in_bound_pct = std::numeric_limits<double>::quiet_NaN();
  double nees_median = std::numeric_limits<double>::quiet_NaN();
  double nees_mean = std::numeric_limits<double>::quiet_NaN();
  /// Position error over distance (%) and rotation error (deg), medians.
  double position_error_pct_median = std::numeric_limits<double>::quiet_NaN();
  double rotation_error_deg_median = std::numeric_limits<double>::quiet_NaN();
  /// Accepted poses more than 20 deg off: the wrong solution of the planar
  /// ambiguity; and of those, the ones whose rotation covariance does not
  /// cover the rotation error (its NEES beyond the chi^2(3) 95 % bound,
  /// 7.81): a wrong rotation claimed.
  uint64_t wrong_solutions = 0;
  uint64_t wrong_solutions_claimed = 0;
  std::vector<WrongTagSolution> wrong;  ///< each of wrong_solutions
  /// RMS of each error over its stated sigma (dx dy dz [camera], droll
  /// dpitch dyaw [tag]): 1 where the covariance is right for that axis.
  Eigen::Matrix<double, 6, 1> normalized_rms = Eigen::Matrix<double, 6, 1>::Zero();
  /// Mean position error [m, camera]: a bias of the images against the
  /// world (timing, extrinsics) shows here.
  Eigen::Vector3d mean_position_error_m = Eigen::Vector3d::Zero();
};

/// Scores `detections` against `world`'s static tags; `T_world_cam_at` gives
/// the true rectified left camera at a capture time.
TagScore ScoreTagDetections(const std::vector<log::rover_msgs::TagDetection>& detections,
                            const World& world,
                            const std::function<Eigen::Isometry3d(Time)>& T_world_cam_at);

/// One report line ("  tags vs truth: ..."), and one per wrong solution.
void ReportTagScore(const TagScore& score, std::ostream& report);

}  // namespace rover::sim::experiments

#endif  // ROVER_HIL_SIM_EXPERIMENTS_TAG_EVALUATION_H_
