#include "estimator/eskf/frame_switcher.h"

#include "core/geometry/so3.h"
#include "core/geometry/yaw.h"

namespace rover::estimator {
namespace {

// The switch Jacobian J (new error = J old error) in block form. With
// R = R_local_body, psi = YawOf(R), Rz = Rz(psi), e = (0, 0, 1) and
// j = dpsi/dtheta (1x3, YawJacobianRight):
//   dp'      = 0
//   dv'      = Rz^T dv + Cv dtheta,                 Cv   = -Rz^T [e]x v e j
//   dtheta'  = Ctheta dtheta,                       Ctheta = I - R^T e j
//   db'      = db
//   dp_c'    = Rz^T (dp_c - dp) + Cp_c dtheta,      Cp_c = -Rz^T [e]x (p_c - p) j
//   dtheta_c'= dtheta_c + Ct_c dtheta,              Ct_c = -R_c^T e j
struct SwitchJacobian {
  Eigen::Matrix3d Rzt;
  Eigen::Matrix3d Cv;
  Eigen::Matrix3d Ctheta;
  std::array<Eigen::Matrix3d, kMaxClones> Cp;
  std::array<Eigen::Matrix3d, kMaxClones> Ct;
  int clone_count = 0;

  // X <- J X for a matrix X with Dim() rows, in place. Clone rows first:
  // they read the old core dp and dtheta rows, which are rewritten last.
  template <typename Derived>
  void ApplyLeft(Eigen::MatrixBase<Derived>& X) const {
    const int cols = static_cast<int>(X.cols());
    Eigen::Matrix<double, 3, kMaxStateDim> tmp;
    const auto dp = X.middleRows(kDp, 3);
    const auto dth = X.middleRows(kDtheta, 3);
    for (int i = 0; i < clone_count; ++i) {
      const size_t s = static_cast<size_t>(i);
      const int off = FilterState::CloneOffset(i);
      auto pc = X.middleRows(off, 3);
      auto tc = X.middleRows(off + 3, 3);
      tmp.leftCols(cols) = pc - dp;
      pc.noalias() = Rzt * tmp.leftCols(cols);
      pc.noalias() += Cp[s] * dth;
      tc.noalias() += Ct[s] * dth;
    }
    auto dv = X.middleRows(kDv, 3);
    tmp.leftCols(cols) = dv;
    dv.noalias() = Rzt * tmp.leftCols(cols);
    dv.noalias() += Cv * dth;
    tmp.leftCols(cols) = dth;
    X.middleRows(kDtheta, 3).noalias() = Ctheta * tmp.leftCols(cols);
    X.middleRows(kDp, 3).setZero();
  }
};

SwitchJacobian MakeJacobian(const FilterState& s, double yaw) {
  const Eigen::Vector3d e = Eigen::Vector3d::UnitZ();
  const Eigen::RowVector3d j = YawJacobianRight(s.core.R_local_body);
  const Eigen::Matrix3d ex = skew(e);
  SwitchJacobian J;
  J.Rzt = Rz(yaw).transpose();
  J.Cv = -J.Rzt * ex * s.core.v_local_m_s * j;
  J.Ctheta = Eigen::Matrix3d::Identity() - s.core.R_local_body.transpose() * e * j;
  J.clone_count = s.clone_count;
  for (int i = 0; i < s.clone_count; ++i) {
    const size_t k = static_cast<size_t>(i);
    const PoseClone& c = s.clones[k];
    J.Cp[k] = -J.Rzt * ex * (c.p_local_body - s.core.p_local_body) * j;
    J.Ct[k] = -c.R_local_body.transpose() * e * j;
  }
  return J;
}

// Transforms nominal values and covariance; returns the yaw of the old pose.
void Transform(FilterState& s, double yaw) {
  s.SyncCrossCovariance();
  const SwitchJacobian J = MakeJacobian(s, yaw);
  const int dim = s.Dim();
  auto P = s.P.topLeftCorner(dim, dim);
  J.ApplyLeft(P);        // J P
  P.transposeInPlace();  // (J P)^T = P J^T
  J.ApplyLeft(P);        // J P J^T
  s.Symmetrize();

  const Eigen::Vector3d p0 = s.core.p_local_body;
  const Eigen::Matrix3d Rzt = Rz(yaw).transpose();
  const Eigen::Quaterniond qzt(Rzt);
  for (int i = 0; i < s.clone_count; ++i) {
    PoseClone& c = s.clones[static_cast<size_t>(i)];
    c.p_local_body = Rzt * (c.p_local_body - p0);
    c.SetAttitude(qzt * c.q_local_body);
  }
  s.core.p_local_body.setZero();
  s.core.v_local_m_s = Rzt * s.core.v_local_m_s;
  s.core.SetAttitude(qzt * s.core.q_local_body);
}

}  // namespace

FrameSwitchRecord FrameSwitcher::Switch(FilterState& state) {
  state.SyncCrossCovariance();
  FrameSwitchRecord record;
  record.stamp = state.core.stamp;
  record.old_frame_id = state.frame_id;
  record.new_frame_id = state.frame_id + 1;
  record.p_old_new = state.core.p_local_body;
  record.yaw_old_new_rad = YawOf(state.core.R_local_body);
  // Covariance of [p; yaw] = A P A^T with A = [I 0 0 0 0; 0 0 j 0 0].
  const Eigen::RowVector3d j = YawJacobianRight(state.core.R_local_body);
  const auto& P = state.P;
  record.covariance.topLeftCorner<3, 3>() = P.block<3, 3>(kDp, kDp);
  const Eigen::Vector3d p_yaw = P.block<3, 3>(kDp, kDtheta) * j.transpose();
  record.covariance.block<3, 1>(0, 3) = p_yaw;
  record.covariance.block<1, 3>(3, 0) = p_yaw.transpose();
  record.covariance(3, 3) = j * P.block<3, 3>(kDtheta, kDtheta) * j.transpose();

  Transform(state, record.yaw_old_new_rad);
  state.frame_id = record.new_frame_id;
  return record;
}

void FrameSwitcher::ResetPositionAndYaw(FilterState& state) {
  Transform(state, YawOf(state.core.R_local_body));
}

}  // namespace rover::estimator
