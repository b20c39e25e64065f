#ifndef ROVER_ESTIMATOR_ESKF_UPDATE_KALMAN_UPDATE_H_
#define ROVER_ESTIMATOR_ESKF_UPDATE_KALMAN_UPDATE_H_

// The EKF update shared by every updater, for a measurement whose Jacobian is
// non-zero only in a few 3-column blocks of the error state (the usual case:
// a wheel update touches v, theta and bg; a relative pose touches two clones).
//
// With U = P H^T and S = H P H^T + R, the gain is K = U S^-1 and the
// covariance update is the Joseph form
//   P+ = (I - K H) P (I - K H)^T + K R K^T = P - K U^T - U K^T + K S K^T,
// evaluated through U, so it costs O(dim^2 m) instead of O(dim^3) and stays
// symmetric positive semi-definite for any gain. Measurement dimension M and
// block count NB are compile-time constants: nothing allocates.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <array>

#include "estimator/eskf/state/filter_state.h"

namespace rover::estimator {

/// A linearised measurement: residual r = z - h(x), Jacobian H = dh/d(error)
/// restricted to NB blocks of 3 columns starting at `block_offsets`, and
/// noise covariance R.
template <int M, int NB>
struct LinearisedMeasurement {
  Eigen::Matrix<double, M, 1> residual = Eigen::Matrix<double, M, 1>::Zero();
  Eigen::Matrix<double, M, 3 * NB> H = Eigen::Matrix<double, M, 3 * NB>::Zero();
  std::array<int, static_cast<size_t>(NB)> block_offsets{};
  Eigen::Matrix<double, M, M> R = Eigen::Matrix<double, M, M>::Identity();
};

/// What an update did.
struct UpdateOutcome {
  bool applied = false;
  bool gated = false;      ///< refused by the chi-square gate
  bool numerical = false;  ///< refused: S not positive definite or non-finite result
  double mahalanobis_sq = 0.0;
};

/// Applies the measurement to `state` unless its squared Mahalanobis
/// distance r^T S^-1 r exceeds `gate` (gate <= 0: no gating). Syncs the
/// cross covariance first.
template <int M, int NB>
UpdateOutcome KalmanUpdate(FilterState& state, const LinearisedMeasurement<M, NB>& z, double gate) {
  UpdateOutcome out;
  state.SyncCrossCovariance();
  const int dim = state.Dim();
  auto P = state.P.topLeftCorner(dim, dim);

  Eigen::Matrix<double, kMaxStateDim, M> U;
  auto Ud = U.topRows(dim);
  Ud.setZero();
  for (int b = 0; b < NB; ++b) {
    Ud.noalias() += P.middleCols(z.block_offsets[static_cast<size_t>(b)], 3) *
                    z.H.template middleCols<3>(3 * b).transpose();
  }
  Eigen::Matrix<double, M, M> S = z.R;
  for (int b = 0; b < NB; ++b) {
    S.noalias() += z.H.template middleCols<3>(3 * b) *
                   U.template block<3, M>(z.block_offsets[static_cast<size_t>(b)], 0);
  }
  S = 0.5 * (S + S.transpose()).eval();
  const Eigen::LLT<Eigen::Matrix<double, M, M>> llt(S);
  if (llt.info() != Eigen::Success) {
    out.numerical = true;
    return out;
  }
  out.mahalanobis_sq = z.residual.dot(llt.solve(z.residual));
  if (!std::isfinite(out.mahalanobis_sq)) {
    out.numerical = true;
    return out;
  }
  if (gate > 0.0 && out.mahalanobis_sq > gate) {
    out.gated = true;
    return out;
  }
  // K = U S^-1, computed as (S^-1 U^T)^T.
  Eigen::Matrix<double, kMaxStateDim, M> K;
  auto Kd = K.topRows(dim);
  Kd = llt.solve(Ud.transpose()).transpose();
  StateVector dx;
  dx.head(dim).noalias() = Kd * z.residual;
  if (!dx.head(dim).allFinite()) {
    out.numerical = true;
    return out;
  }
  Eigen::Matrix<double, kMaxStateDim, M> KS;
  KS.topRows(dim).noalias() = Kd * S;
  // P - K U^T - U K^T + K S K^T, accumulated symmetrically.
  Eigen::Matrix<double, kMaxStateDim, M> W;  // K S - U, so the sum is P + W K^T - K U^T
  W.topRows(dim) = KS.topRows(dim) - Ud;
  P.noalias() += W.topRows(dim) * Kd.transpose();
  P.noalias() -= Kd * Ud.transpose();
  state.Symmetrize();
  state.ApplyCorrection(dx);
  out.applied = true;
  return out;
}

}  // namespace rover::estimator

#endif  // ROVER_ESTIMATOR_ESKF_UPDATE_KALMAN_UPDATE_H_
