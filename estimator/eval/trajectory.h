#ifndef ROVER_ESTIMATOR_EVAL_TRAJECTORY_H_
#define ROVER_ESTIMATOR_EVAL_TRAJECTORY_H_

// A time-ordered sequence of stamped body poses T_world_body, the common
// currency of the evaluation tools (readers produce it, association, alignment
// and the metrics consume it).
//
// Error convention of the optional pose covariance (the ESKF's): the 6x6
// matrix is over [dp; dtheta] (metres, radians) with
//   p_true = p_est + dp,        R_true = R_est * ExpSO3(dtheta),
// i.e. the position error in the world frame and the attitude error on the
// body (right) side.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "core/geometry/se3.h"
#include "core/time/time.h"

namespace rover::eval {

/// One stamped pose of the body in the trajectory's world frame.
struct PoseSample {
  Time stamp;
  Eigen::Vector3d p_world_body = Eigen::Vector3d::Zero();  ///< [m]
  Eigen::Quaterniond q_world_body = Eigen::Quaterniond::Identity();
  /// Covariance over [dp; dtheta] (see the header comment), [m^2], [m rad], [rad^2].
  std::optional<Matrix6d> covariance;
  /// Velocity of the body in the world frame [m/s], when the source has it.
  std::optional<Eigen::Vector3d> v_world_body_m_s;

  /// The pose as a rigid transform (maps body points into the world frame).
  Eigen::Isometry3d T_world_body() const;
};

/// Returns q scaled to unit norm, or q itself (bit for bit) when its norm is
/// already 1 to within a few ulp, so that quaternions written at full precision
/// read back exactly. q must be non-zero.
Eigen::Quaterniond UnitQuaternion(const Eigen::Quaterniond& q);

/// Checks one sample: finite stamp-independent values, a unit quaternion
/// (|q| within 1e-6 of 1) and, if present, a finite symmetric covariance with
/// a non-negative diagonal. Returns an empty string when the sample is valid,
/// otherwise a description of the form "expected ..., found ...".
std::string CheckPoseSample(const PoseSample& sample);

/// Time-ordered poses with strictly increasing stamps.
class Trajectory {
 public:
  Trajectory() = default;
  /// Wraps `samples` without checking them (call Validate() for that).
  explicit Trajectory(std::vector<PoseSample> samples, std::string source = "");

  /// Appends a sample without checking it.
  void Append(const PoseSample& sample) { samples_.push_back(sample); }

  const std::vector<PoseSample>& samples() const { return samples_; }
  std::vector<PoseSample>& mutable_samples() { return samples_; }
  std::size_t size() const { return samples_.size(); }
  bool empty() const { return samples_.empty(); }
  const PoseSample& operator[](std::size_t i) const { return samples_[i]; }
  std::vector<PoseSample>::const_iterator begin() const { return samples_.begin(); }
  std::vector<PoseSample>::const_iterator end() const { return samples_.end(); }

  /// Where the trajectory came from (a file path, or a description); used to
  /// prefix error messages.
  const std::string& source() const { return source_; }
  void set_source(std::string source) { source_ = std::move(source); }

  /// True if at least one sample carries a covariance.
  bool HasCovariance() const;
  /// Time between the first and the last sample (zero when fewer than two).
  Duration Span() const;

  /// Throws EvalError ("SOURCE: sample I (t = ... s): expected ..., found ...")
  /// unless every sample passes CheckPoseSample() and stamps strictly increase.
  void Validate() const;

  /// Returns the trajectory expressed in another world frame:
  /// T_new_body = T_new_world * T_world_body, with positions additionally
  /// scaled about the new origin: p_new = scale * R_new_world * p + t_new_world.
  /// Velocities and covariances are rotated (and scaled) accordingly; the
  /// body-side attitude covariance is unchanged.
  Trajectory Transformed(const Eigen::Isometry3d& T_new_world, double scale = 1.0) const;

 private:
  std::vector<PoseSample> samples_;
  std::string source_;
};

}  // namespace rover::eval

#endif  // ROVER_ESTIMATOR_EVAL_TRAJECTORY_H_
