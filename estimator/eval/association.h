#ifndef ROVER_ESTIMATOR_EVAL_ASSOCIATION_H_
#define ROVER_ESTIMATOR_EVAL_ASSOCIATION_H_

// Time association of an estimate with its ground truth: the ground truth is
// interpolated (linear in position, slerp in rotation) at every estimate stamp.

#include <cstddef>
#include <optional>
#include <vector>

#include "core/time/time.h"
#include "estimator/eval/trajectory.h"

namespace rover::eval {

struct AssociationOptions {
  /// Largest spacing of the two ground-truth samples bracketing an estimate
  /// stamp; estimates inside a larger ground-truth gap are skipped.
  Duration max_gap = Duration::Milliseconds(20);
  /// Constant clock offset: the estimate stamped t is compared with the
  /// ground truth at t + time_offset.
  Duration time_offset = Duration::Zero();
  /// An estimate stamp this close to a ground-truth sample uses that sample as
  /// it is (no bracketing needed). Covers files whose stamps were rounded,
  /// e.g. the OpenVINS EuRoC ground truth, off by 256 ns from the image stamps.
  Duration snap_tolerance = Duration::Microseconds(1);
};

/// One estimate sample with the ground truth at the same time.
struct AssociatedPose {
  Time stamp;                      ///< Estimate stamp.
  std::size_t estimate_index = 0;  ///< Index of the sample in the estimate trajectory.
  Eigen::Isometry3d T_world_body_estimate = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_world_body_truth = Eigen::Isometry3d::Identity();
  /// The estimate's covariance over [dp; dtheta] (trajectory.h), if it has one.
  std::optional<Matrix6d> covariance;
};

/// Result of Associate().
struct Association {
  std::vector<AssociatedPose> poses;  ///< In estimate order.
  std::size_t skipped_outside = 0;    ///< Estimates before or after the ground-truth span.
  std::size_t skipped_gap = 0;        ///< Estimates inside a ground-truth gap > max_gap.
};

/// The pose between `a` and `b` at time t (a.stamp <= t <= b.stamp, a.stamp <
/// b.stamp): position and velocity linear, rotation by slerp on the shorter arc
/// (q_a * Exp(f * Log(q_a^-1 q_b)), f = (t - a) / (b - a)). The covariance is
/// taken from the nearer sample.
PoseSample InterpolatePose(const PoseSample& a, const PoseSample& b, Time t);

/// `trajectory` at time t: a sample within `snap_tolerance` of t as it is,
/// otherwise interpolated between the bracketing samples if they are at most
/// `max_gap` apart; nullopt outside the span or across a larger gap.
/// `trajectory` must have strictly increasing stamps.
std::optional<PoseSample> PoseAt(const Trajectory& trajectory, Time t, Duration max_gap,
                                 Duration snap_tolerance = Duration::Microseconds(1));

/// Associates every estimate sample with the ground truth at its stamp plus
/// options.time_offset (see AssociationOptions). Estimates that cannot be
/// associated are counted, not returned. Both trajectories must have strictly
/// increasing stamps. Never throws; an empty result means no overlap.
Association Associate(const Trajectory& estimate, const Trajectory& truth,
                      const AssociationOptions& options = {});

}  // namespace rover::eval

#endif  // ROVER_ESTIMATOR_EVAL_ASSOCIATION_H_
