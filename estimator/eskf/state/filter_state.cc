#include "estimator/eskf/state/filter_state.h"

#include <cmath>

#include "core/geometry/quaternion.h"

namespace rover::estimator {

void NominalState::SetAttitude(const Eigen::Quaterniond& q) {
  q_local_body = q.normalized();
  R_local_body = q_local_body.toRotationMatrix();
}

void PoseClone::SetAttitude(const Eigen::Quaterniond& q) {
  q_local_body = q.normalized();
  R_local_body = q_local_body.toRotationMatrix();
}

FilterState::FilterState() {
  P.setZero();
  pending_transition.setIdentity();
}

void FilterState::SyncCrossCovariance() {
  if (clone_count > 0) {
    const int n = kCloneDim * clone_count;
    auto cross = P.block(0, kCoreDim, kCoreDim, n);
    // 15 x 6n product into fixed-capacity storage: no heap (Eigen uses the
    // compile-time maximum sizes of the blocks for its temporaries).
    Eigen::Matrix<double, kCoreDim, kCloneDim * kMaxClones> updated;
    updated.leftCols(n).noalias() = pending_transition * cross;
    cross = updated.leftCols(n);
    P.block(kCoreDim, 0, n, kCoreDim) = cross.transpose();
  }
  pending_transition.setIdentity();
}

int FilterState::AppendCloneOfCore() {
  Eigen::Matrix<double, 6, 15> J = Eigen::Matrix<double, 6, 15>::Zero();
  J.block<3, 3>(0, kDp).setIdentity();
  J.block<3, 3>(3, kDtheta).setIdentity();
  PoseClone pose;
  pose.stamp = core.stamp;
  pose.p_local_body = core.p_local_body;
  pose.q_local_body = core.q_local_body;
  pose.R_local_body = core.R_local_body;
  return AppendCloneFromCore(J, pose);
}

int FilterState::AppendCloneFromCore(const Eigen::Matrix<double, 6, 15>& J, const PoseClone& pose) {
  const int i = clone_count;
  const int dim = Dim();
  const int off = CloneOffset(i);
  // New rows: J times the core rows of the (synced) joint covariance.
  Eigen::Matrix<double, 6, kMaxStateDim> rows;
  rows.leftCols(dim).noalias() = J * P.block(0, 0, kCoreDim, dim);
  P.block(off, 0, kCloneDim, dim) = rows.leftCols(dim);
  P.block(0, off, dim, kCloneDim) = rows.leftCols(dim).transpose();
  P.block<kCloneDim, kCloneDim>(off, off).noalias() = rows.leftCols(kCoreDim) * J.transpose();
  clones[static_cast<size_t>(i)] = pose;
  ++clone_count;
  return i;
}

void FilterState::RemoveClone(int i) {
  const int dim = Dim();
  const int off = CloneOffset(i);
  const int tail = dim - off - kCloneDim;
  if (tail > 0) {
    // Shift the later rows up and the later columns left (in that order, so
    // every block moves once; ranges may overlap, so copy through .eval()-free
    // row-by-row moves in increasing order).
    for (int r = off; r < off + tail; ++r) P.row(r).head(dim) = P.row(r + kCloneDim).head(dim);
    for (int c = off; c < off + tail; ++c) P.col(c).head(dim) = P.col(c + kCloneDim).head(dim);
    for (int k = i; k + 1 < clone_count; ++k) {
      clones[static_cast<size_t>(k)] = clones[static_cast<size_t>(k + 1)];
    }
  }
  --clone_count;
  const int new_dim = Dim();
  P.block(new_dim, 0, kCloneDim, kMaxStateDim).setZero();
  P.block(0, new_dim, kMaxStateDim, kCloneDim).setZero();
}

int FilterState::FindClone(Time stamp, Duration tolerance) const {
  for (int i = 0; i < clone_count; ++i) {
    Duration d = clones[static_cast<size_t>(i)].stamp - stamp;
    if (d < Duration::Zero()) d = -d;
    if (d <= tolerance) return i;
  }
  return -1;
}

void FilterState::ApplyCorrection(const StateVector& dx) {
  core.p_local_body += dx.segment<3>(kDp);
  core.v_local_m_s += dx.segment<3>(kDv);
  core.SetAttitude(Boxplus(core.q_local_body, dx.segment<3>(kDtheta)));
  core.accel_bias_m_s2 += dx.segment<3>(kDba);
  core.gyro_bias_rad_s += dx.segment<3>(kDbg);
  for (int i = 0; i < clone_count; ++i) {
    PoseClone& c = clones[static_cast<size_t>(i)];
    const int off = CloneOffset(i);
    c.p_local_body += dx.segment<3>(off);
    c.SetAttitude(Boxplus(c.q_local_body, dx.segment<3>(off + 3)));
  }
}

void FilterState::Symmetrize() {
  const int dim = Dim();
  for (int r = 0; r < dim; ++r) {
    for (int c = r + 1; c < dim; ++c) {
      const double m = 0.5 * (P(r, c) + P(c, r));
      P(r, c) = m;
      P(c, r) = m;
    }
  }
}

bool FilterState::IsFinite() const {
  if (!core.p_local_body.allFinite() || !core.v_local_m_s.allFinite() ||
      !core.q_local_body.coeffs().allFinite() || !core.accel_bias_m_s2.allFinite() ||
      !core.gyro_bias_rad_s.allFinite()) {
    return false;
  }
  const int dim = Dim();
  for (int k = 0; k < dim; ++k) {
    if (!std::isfinite(P(k, k)) || P(k, k) < 0.0) return false;
  }
  return true;
}

}  // namespace rover::estimator
