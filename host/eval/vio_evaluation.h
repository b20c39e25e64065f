#ifndef ROVER_HOST_EVAL_VIO_EVALUATION_H_
#define ROVER_HOST_EVAL_VIO_EVALUATION_H_

// The evaluation math of `rover-eval vio`, kept apart from the command so it
// can be tested on synthetic inputs with known answers:
//  * VoChain: the VO-alone trajectory from the per-frame T_odom_body, with
//    chains that restart after a tracking loss re-anchored to the previous
//    chain's last pose;
//  * ComputeDeltaPoseNees: consistency of the emitted relative poses against
//    ground truth, with the bounds for the mean NEES;
//  * QuoteRpe: which RPE segment length a single figure quotes;
//  * AlignAtPose / EvaluateAlignedAtStart: errors of an estimate aligned
//    only at its first pose.

#include <Eigen/Geometry>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "core/stats/chi_square.h"
#include "core/time/time.h"
#include "estimator/eskf/eskf_input.h"
#include "estimator/eval/alignment.h"
#include "estimator/eval/association.h"
#include "estimator/eval/ate.h"
#include "estimator/eval/nees.h"
#include "estimator/eval/rpe.h"
#include "estimator/eval/trajectory.h"

namespace rover::host::eval {

/// Chains the VO's per-frame poses into one trajectory. The VO's odometry
/// frame is the body at the first keyframe of a chain; after a tracking loss
/// the VO starts a new chain whose poses are relative to its own first
/// keyframe. Each new chain is re-anchored so that its first pose coincides
/// with the last chained pose of the previous chain (the motion across the
/// gap is unknown to the VO and counted as zero).
class VoChain {
 public:
  /// Adds the VO pose of the frame captured at `capture`. `starts_chain`
  /// marks the first frame of a chain (the first keyframe, or a restart).
  /// The first pose ever starts the first chain whatever `starts_chain` says.
  /// Frames not after the previous one are ignored (returns false).
  bool Add(Time capture, const Eigen::Isometry3d& T_odom_body, bool starts_chain);

  /// The chained poses, in the frame of the first chain's first keyframe.
  const rover::eval::Trajectory& trajectory() const { return trajectory_; }
  /// Chains started after the first one.
  int restarts() const { return restarts_; }

 private:
  rover::eval::Trajectory trajectory_;
  Eigen::Isometry3d T_chain_odom_ = Eigen::Isometry3d::Identity();  ///< current anchor
  int restarts_ = 0;
};

/// Consistency of the VO's relative poses against ground truth.
///
/// For each measurement the true T_bodyfrom_bodyto is T_world_from^-1 *
/// T_world_to from the ground truth interpolated at from_stamp and to_stamp.
/// With the filter's noise convention p_meas = p_true + n_p, R_meas = R_true *
/// Exp(n_theta), the NEES is n^T Sigma^-1 n over n = [n_p; n_theta] (6 dof),
/// n_p^T Sigma_pp^-1 n_p (translation, 3 dof) and n_theta^T Sigma_tt^-1
/// n_theta (rotation, 3 dof), with the marginal blocks of the covariance.
struct DeltaPoseNees {
  std::size_t measurements = 0;   ///< relative poses given
  std::size_t without_truth = 0;  ///< no ground truth at from_stamp or to_stamp
  rover::eval::NeesResult nees;   ///< per-measurement NEES and means
  /// RMS over the evaluated measurements of |n_p| [m] and |n_theta| [deg],
  /// and what the stated covariances predict for them: sqrt(mean(trace)).
  double rms_translation_error_m = std::numeric_limits<double>::quiet_NaN();
  double rms_rotation_error_deg = std::numeric_limits<double>::quiet_NaN();
  double rms_translation_sigma_m = std::numeric_limits<double>::quiet_NaN();
  double rms_rotation_sigma_deg = std::numeric_limits<double>::quiet_NaN();
  /// Two-sided 95 % bounds of the mean of N = nees.samples.size() NEES
  /// samples: chi2(6 N) / N and chi2(3 N) / N quantiles (NaN without samples).
  rover::stats::ChiSquareInterval bounds_6dof{std::numeric_limits<double>::quiet_NaN(),
                                              std::numeric_limits<double>::quiet_NaN()};
  rover::stats::ChiSquareInterval bounds_3dof{std::numeric_limits<double>::quiet_NaN(),
                                              std::numeric_limits<double>::quiet_NaN()};
  /// The 6-dof mean lies inside bounds_6dof.
  bool pose_inside = false;
};

/// Computes DeltaPoseNees of `measurements` against `truth` (interpolated
/// across ground-truth gaps up to `max_gap`).
DeltaPoseNees ComputeDeltaPoseNees(
    const std::vector<estimator::RelativePoseMeasurement>& measurements,
    const rover::eval::Trajectory& truth, Duration max_gap);

/// The RPE figure to quote as one number: the segment length that
/// RpeResult::Headline(preferred_m) picks.
struct RpeQuote {
  double length_m = std::numeric_limits<double>::quiet_NaN();            ///< NaN: no segment
  double translation_pct = std::numeric_limits<double>::quiet_NaN();     ///< mean [%]
  double rotation_deg_per_m = std::numeric_limits<double>::quiet_NaN();  ///< mean [deg/m]
  std::size_t segments = 0;
  /// One line for the report: which length is quoted and why.
  std::string note;
};

/// Quotes `rpe` at `preferred_m`, or at the longest shorter length with
/// segments when the trajectory is too short (the note says so), or nothing
/// (NaN figures) when no length has segments. `distance_m` is the ground-truth
/// path length, used in the note.
RpeQuote QuoteRpe(const rover::eval::RpeResult& rpe, double distance_m, double preferred_m = 10.0);

/// The alignment that maps the estimate pose of `pose` exactly onto its
/// ground-truth pose: kSe3 (rotation + translation) or kFourDof (yaw +
/// translation; both frames gravity-aligned, z up, so position and heading
/// match). The estimate is aligned at this one pose only. Throws
/// std::invalid_argument for other methods.
rover::eval::Alignment AlignAtPose(const rover::eval::AssociatedPose& pose,
                                   rover::eval::AlignmentMethod method);

/// Errors of an estimate aligned only at its first pose (AlignAtPose), the
/// drift an odometry accumulates from its start.
struct StartAlignedErrors {
  rover::eval::AteResult ate;  ///< NaN statistics for no poses
  /// Position error of the last pose [m] (NaN for no poses).
  double final_error_m = std::numeric_limits<double>::quiet_NaN();
};

/// Aligns `poses` at the first one with `method` and returns the errors.
StartAlignedErrors EvaluateAlignedAtStart(const std::vector<rover::eval::AssociatedPose>& poses,
                                          rover::eval::AlignmentMethod method);

}  // namespace rover::host::eval

#endif  // ROVER_HOST_EVAL_VIO_EVALUATION_H_
