#ifndef ROVER_ESTIMATOR_ESKF_STATE_FILTER_STATE_H_
#define ROVER_ESTIMATOR_ESKF_STATE_FILTER_STATE_H_

// The filter's state: the nominal IMU state, the pose clones and the joint
// error covariance, all in fixed-size storage so nothing allocates after
// construction.
//
// Error vector layout (dimension 15 + 6 n for n clones):
//   [dp(3) dv(3) dtheta(3) dba(3) dbg(3) | clone 0: dp(3) dtheta(3) | clone 1 ...]
// with p_true = p + dp, v_true = v + dv, R_true = R Exp(dtheta) (body-side),
// b_true = b + db, and likewise for each clone. Clones are kept in capture
// order: clone 0 is the oldest.
//
// Lazy cross-covariance: between updates, propagation only touches the 15x15
// core block and accumulates the product of the step transitions in
// `pending_transition`; the core-clone block is brought up to date by
// SyncCrossCovariance() (one 15x15 by 15x6n product) before anything reads
// it. This keeps an IMU step independent of the number of clones and is
// exactly equivalent to updating the cross block every step.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>

#include "core/time/time.h"
#include "estimator/eskf/eskf_options.h"

namespace rover::estimator {

inline constexpr int kCoreDim = 15;
inline constexpr int kCloneDim = 6;
inline constexpr int kMaxStateDim = kCoreDim + kCloneDim * kMaxClones;

/// Offsets of the error-state blocks inside the core.
enum CoreBlock : int { kDp = 0, kDv = 3, kDtheta = 6, kDba = 9, kDbg = 12 };

using CovarianceMatrix = Eigen::Matrix<double, kMaxStateDim, kMaxStateDim>;
using StateVector = Eigen::Matrix<double, kMaxStateDim, 1>;
using Matrix15d = Eigen::Matrix<double, 15, 15>;

/// The nominal IMU state at `stamp`.
struct NominalState {
  Time stamp;
  Eigen::Vector3d p_local_body = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_local_m_s = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_local_body = Eigen::Quaterniond::Identity();
  Eigen::Matrix3d R_local_body = Eigen::Matrix3d::Identity();  ///< kept equal to q_local_body
  Eigen::Vector3d accel_bias_m_s2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_bias_rad_s = Eigen::Vector3d::Zero();

  /// Sets q and its rotation matrix together (q is normalised).
  void SetAttitude(const Eigen::Quaterniond& q);
};

/// A copy of the body pose at a camera capture time.
struct PoseClone {
  Time stamp;
  Eigen::Vector3d p_local_body = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_local_body = Eigen::Quaterniond::Identity();
  Eigen::Matrix3d R_local_body = Eigen::Matrix3d::Identity();
  bool keyframe = false;  ///< a later measurement may start from it
  bool measured = false;  ///< a measurement already ended at it

  void SetAttitude(const Eigen::Quaterniond& q);
};

class FilterState {
 public:
  FilterState();

  NominalState core;
  std::array<PoseClone, kMaxClones> clones;
  int clone_count = 0;
  /// Joint covariance; only the top-left Dim() x Dim() block is meaningful.
  CovarianceMatrix P;
  /// Product of the step transitions since the last SyncCrossCovariance().
  Matrix15d pending_transition;
  uint32_t frame_id = 0;

  int Dim() const { return kCoreDim + kCloneDim * clone_count; }
  static int CloneOffset(int i) { return kCoreDim + kCloneDim * i; }

  /// Applies pending_transition to the core-clone cross block and resets it.
  void SyncCrossCovariance();

  /// Appends a clone of the current core pose (the caller has synced the
  /// cross covariance and made room). Returns its index.
  int AppendCloneOfCore();

  /// Appends a clone whose error is J * (core error) for a 6x15 Jacobian J
  /// (used for clones extrapolated back in time). Returns its index.
  int AppendCloneFromCore(const Eigen::Matrix<double, 6, 15>& J, const PoseClone& pose);

  /// Removes clone i and its rows and columns (marginalisation: for a
  /// Gaussian, dropping the block is exact).
  void RemoveClone(int i);

  /// Index of the clone captured at `stamp` (within `tolerance`), or -1.
  int FindClone(Time stamp, Duration tolerance) const;

  /// Adds the error-state correction dx (first Dim() entries) to the nominal
  /// state and the clones.
  void ApplyCorrection(const StateVector& dx);

  /// Makes the active block exactly symmetric.
  void Symmetrize();

  /// True if every nominal value and the covariance diagonal are finite and
  /// the diagonal is non-negative.
  bool IsFinite() const;
};

}  // namespace rover::estimator

#endif  // ROVER_ESTIMATOR_ESKF_STATE_FILTER_STATE_H_
