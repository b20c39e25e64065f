#include "mapping/graph/relative_pose_2d_cost.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <numbers>

namespace rover::mapping {
namespace {

Eigen::Matrix2d Rot(double theta) {
  const double c = std::cos(theta);
  const double s = std::sin(theta);
  return (Eigen::Matrix2d() << c, -s, s, c).finished();
}

}  // namespace

double WrapAngle(double angle_rad) {
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  double a = std::fmod(angle_rad + std::numbers::pi, kTwoPi);
  if (a < 0.0) a += kTwoPi;
  return a - std::numbers::pi;
}

RelativePose2dCost::RelativePose2dCost(const Eigen::Vector3d& measurement,
                                       const Eigen::Matrix3d& information)
    : t_ij_(measurement.head<2>()),
      theta_ij_(measurement(2)),
      R_ij_(Rot(measurement(2))),
      sqrt_information_(Eigen::LLT<Eigen::Matrix3d>(information).matrixU()) {}

bool RelativePose2dCost::Evaluate(double const* const* parameters, double* residuals,
                                  double** jacobians) const {
  const Eigen::Vector2d ti(parameters[0][0], parameters[0][1]);
  const Eigen::Vector2d tj(parameters[1][0], parameters[1][1]);
  const double thi = parameters[0][2];
  const double thj = parameters[1][2];
  const double c = std::cos(thi);
  const double s = std::sin(thi);
  Eigen::Matrix2d RiT;
  RiT << c, s, -s, c;
  const Eigen::Vector2d d = tj - ti;
  Eigen::Vector3d e;
  e.head<2>() = R_ij_.transpose() * (RiT * d - t_ij_);
  e(2) = WrapAngle(thj - thi - theta_ij_);
  Eigen::Map<Eigen::Vector3d>{residuals} = sqrt_information_ * e;
  if (jacobians == nullptr) return true;
  using RowJacobian = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
  const Eigen::Matrix2d A = R_ij_.transpose() * RiT;
  if (jacobians[0] != nullptr) {
    Eigen::Matrix2d dRiT;
    dRiT << -s, c, -c, -s;
    Eigen::Matrix3d J = Eigen::Matrix3d::Zero();
    J.topLeftCorner<2, 2>() = -A;
    J.block<2, 1>(0, 2) = R_ij_.transpose() * dRiT * d;
    J(2, 2) = -1.0;
    Eigen::Map<RowJacobian>{jacobians[0]} = sqrt_information_ * J;
  }
  if (jacobians[1] != nullptr) {
    Eigen::Matrix3d J = Eigen::Matrix3d::Zero();
    J.topLeftCorner<2, 2>() = A;
    J(2, 2) = 1.0;
    Eigen::Map<RowJacobian>{jacobians[1]} = sqrt_information_ * J;
  }
  return true;
}

}  // namespace rover::mapping
