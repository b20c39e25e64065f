#ifndef ROVER_ESTIMATOR_EVAL_ALIGNMENT_H_
#define ROVER_ESTIMATOR_EVAL_ALIGNMENT_H_

// Alignment of an estimated trajectory with its ground truth before computing
// errors: the transform T_truth_estimate (and scale, for Sim(3)) that
// minimises the sum of squared position differences
//   sum_i | p_truth_i - (s * R * p_estimate_i + t) |^2
// over the associated poses, in closed form:
//  * kSe3:     rotation + translation (Umeyama / Horn, scale fixed to 1);
//  * kSim3:    rotation + translation + scale (Umeyama);
//  * kFourDof: yaw about z + translation, for visual-inertial estimates whose
//              roll and pitch are observable from gravity. The yaw is
//              atan2(sum(x_e * y_t - y_e * x_t), sum(x_e * x_t + y_e * y_t))
//              over the centred horizontal coordinates (the horizontal
//              cross-covariance), then t = mean_truth - Rz(yaw) * mean_estimate;
//  * kNone:    identity.
// Frames are assumed gravity-aligned with z up for kFourDof.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>
#include <string_view>
#include <vector>

#include "estimator/eval/association.h"

namespace rover::eval {

enum class AlignmentMethod { kNone, kSe3, kSim3, kFourDof };

/// "none", "se3", "sim3", "4dof".
std::string_view ToString(AlignmentMethod method);
/// Inverse of ToString(); nullopt for an unknown name.
std::optional<AlignmentMethod> ParseAlignmentMethod(std::string_view name);

struct AlignmentOptions {
  AlignmentMethod method = AlignmentMethod::kSe3;
  /// Use only the first N associated poses to estimate the alignment (0: all).
  std::size_t first_poses = 0;
  /// Use only the poses within this time of the first associated pose
  /// (zero: all). Combined with first_poses, both limits apply.
  Duration first_duration = Duration::Zero();
};

/// A similarity transform from the estimate's world frame into the truth's:
///   p_truth = scale * R * p_estimate + t,   R_truth_body = R * R_estimate_body.
struct Alignment {
  AlignmentMethod method = AlignmentMethod::kNone;
  Eigen::Isometry3d T_truth_estimate = Eigen::Isometry3d::Identity();  ///< R and t [m].
  double scale = 1.0;                                                  ///< 1 except for kSim3.
  std::size_t poses_used = 0;  ///< Poses the alignment was estimated from.
  /// RMS distance of those estimate positions from their centroid [m]
  /// (horizontal only for kFourDof). When it is small compared with the
  /// position errors (a short or stationary trajectory) the rotation of the
  /// alignment is poorly determined and fits noise.
  double spread_m = 0.0;

  /// Applies the alignment to a pose of the estimate.
  Eigen::Isometry3d Apply(const Eigen::Isometry3d& T_estimate_body) const;
};

/// Umeyama's closed-form least-squares alignment of `estimate` onto `truth`
/// (same length, corresponding points); with_scale selects Sim(3) over SE(3).
/// Throws EvalError for fewer than 3 points or different lengths. Points that
/// are all collinear leave the rotation about that line undetermined.
Alignment AlignUmeyama(const std::vector<Eigen::Vector3d>& estimate,
                       const std::vector<Eigen::Vector3d>& truth, bool with_scale);

/// Closed-form yaw + translation alignment (see the header comment). Throws
/// EvalError for fewer than 2 points or different lengths. With no horizontal
/// spread the yaw is 0.
Alignment AlignFourDof(const std::vector<Eigen::Vector3d>& estimate,
                       const std::vector<Eigen::Vector3d>& truth);

/// Estimates the alignment of options.method from the positions of the
/// associated poses (restricted by options.first_poses / first_duration).
/// Throws EvalError if there are too few poses for the method.
Alignment ComputeAlignment(const std::vector<AssociatedPose>& poses,
                           const AlignmentOptions& options = {});

/// Returns `poses` with every estimate pose mapped into the truth frame by
/// `alignment`; covariances are rotated (and scaled) to match, the body-side
/// attitude part is unchanged.
std::vector<AssociatedPose> ApplyAlignment(const Alignment& alignment,
                                           std::vector<AssociatedPose> poses);

}  // namespace rover::eval

#endif  // ROVER_ESTIMATOR_EVAL_ALIGNMENT_H_
