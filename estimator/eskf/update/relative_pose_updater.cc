#include "estimator/eskf/update/relative_pose_updater.h"

#include "core/geometry/so3.h"
#include "estimator/eskf/update/chi_square_gate.h"

namespace rover::estimator {

RelativePoseUpdater::RelativePoseUpdater(const RelativePoseOptions& options)
    : options_(options), gate_(ChiSquareGate(6, options.gate_probability)) {}

LinearisedMeasurement<6, 4> RelativePoseUpdater::Linearise(const FilterState& state,
                                                           const RelativePoseMeasurement& z, int ia,
                                                           int ib) const {
  const PoseClone& a = state.clones[static_cast<size_t>(ia)];
  const PoseClone& b = state.clones[static_cast<size_t>(ib)];
  const Eigen::Matrix3d Rat = a.R_local_body.transpose();
  const Eigen::Vector3d p_ab = Rat * (b.p_local_body - a.p_local_body);
  const Eigen::Matrix3d R_ab = Rat * b.R_local_body;
  const Eigen::Matrix3d R_meas = z.q_from_to.normalized().toRotationMatrix();
  const Eigen::Vector3d r_rot = LogSO3(R_ab.transpose() * R_meas);
  const Eigen::Matrix3d Jl_inv = LeftJacobianInverseSO3(r_rot);
  const Eigen::Matrix3d Jr_inv = RightJacobianInverseSO3(r_rot);

  LinearisedMeasurement<6, 4> m;
  const int oa = FilterState::CloneOffset(ia);
  const int ob = FilterState::CloneOffset(ib);
  m.block_offsets = {oa, oa + 3, ob, ob + 3};
  m.residual.head<3>() = z.p_from_to - p_ab;
  m.residual.tail<3>() = r_rot;
  // Columns: [dp_a | dtheta_a | dp_b | dtheta_b].
  m.H.block<3, 3>(0, 0) = -Rat;
  m.H.block<3, 3>(0, 3) = skew(p_ab);
  m.H.block<3, 3>(0, 6) = Rat;
  m.H.block<3, 3>(3, 3) = -Jl_inv * R_ab.transpose();
  m.H.block<3, 3>(3, 9) = Jl_inv;
  Matrix6d T = Matrix6d::Identity();
  T.block<3, 3>(3, 3) = Jr_inv;
  m.R = options_.covariance_inflation * T * z.covariance * T.transpose();
  return m;
}

UpdateOutcome RelativePoseUpdater::Update(FilterState& state, const RelativePoseMeasurement& z,
                                          int ia, int ib) const {
  state.SyncCrossCovariance();
  return KalmanUpdate(state, Linearise(state, z, ia, ib), gate_);
}

}  // namespace rover::estimator
