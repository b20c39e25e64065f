// Analytic Jacobians of every cost function of mapping/graph against central
// differences through the manifold (tangent space), at random seeded poses.

#include <ceres/cost_function.h>
#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <vector>

#include "core/geometry/so3.h"
#include "mapping/graph/chordal_pose_2d_cost.h"
#include "mapping/graph/chordal_pose_3d_cost.h"
#include "mapping/graph/pose_manifold.h"
#include "mapping/graph/relative_pose_2d_cost.h"
#include "mapping/graph/relative_pose_3d_cost.h"

namespace rover::mapping {
namespace {

// Compares the tangent-space Jacobian (ambient Jacobian times PlusJacobian)
// with central differences of the residual along Plus(x, h e_k).
void CheckJacobians(const ceres::CostFunction& cost, std::vector<std::vector<double>> params,
                    const std::vector<const ceres::Manifold*>& manifolds, double tol) {
  const int m = cost.num_residuals();
  const size_t nb = params.size();
  std::vector<const double*> ptrs(nb);
  for (size_t b = 0; b < nb; ++b) ptrs[b] = params[b].data();
  std::vector<std::vector<double>> jac(nb);
  std::vector<double*> jptrs(nb);
  for (size_t b = 0; b < nb; ++b) {
    jac[b].assign(static_cast<size_t>(m) * params[b].size(), 0.0);
    jptrs[b] = jac[b].data();
  }
  std::vector<double> r(static_cast<size_t>(m));
  ASSERT_TRUE(cost.Evaluate(ptrs.data(), r.data(), jptrs.data()));
  for (size_t b = 0; b < nb; ++b) {
    const int ambient = static_cast<int>(params[b].size());
    const int tangent = manifolds[b] ? manifolds[b]->TangentSize() : ambient;
    Eigen::MatrixXd plus_jacobian = Eigen::MatrixXd::Identity(ambient, tangent);
    if (manifolds[b]) {
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> pj(ambient, tangent);
      manifolds[b]->PlusJacobian(params[b].data(), pj.data());
      plus_jacobian = pj;
    }
    const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>
        J_ambient(jac[b].data(), m, ambient);
    const Eigen::MatrixXd J = J_ambient * plus_jacobian;
    Eigen::MatrixXd N(m, tangent);
    const double h = 1e-6;
    for (int k = 0; k < tangent; ++k) {
      Eigen::VectorXd rp(m), rm(m);
      for (const double sign : {1.0, -1.0}) {
        std::vector<double> delta(static_cast<size_t>(tangent), 0.0);
        delta[static_cast<size_t>(k)] = sign * h;
        std::vector<double> moved(params[b].size());
        if (manifolds[b]) {
          manifolds[b]->Plus(params[b].data(), delta.data(), moved.data());
        } else {
          for (size_t i = 0; i < moved.size(); ++i) moved[i] = params[b][i] + delta[i];
        }
        std::vector<const double*> p2 = ptrs;
        p2[b] = moved.data();
        Eigen::VectorXd& out = sign > 0 ? rp : rm;
        ASSERT_TRUE(cost.Evaluate(p2.data(), out.data(), nullptr));
      }
      N.col(k) = (rp - rm) / (2.0 * h);
    }
    EXPECT_LT((J - N).cwiseAbs().maxCoeff(), tol) << "block " << b << "\nanalytic:\n"
                                                  << J << "\nnumeric:\n"
                                                  << N;
  }
}

class CostFunctionTest : public ::testing::Test {
 protected:
  Eigen::Isometry3d RandomPose(double angle = 2.5) {
    std::normal_distribution<double> n(0.0, 1.0);
    const Eigen::Vector3d axis = Eigen::Vector3d(n(rng_), n(rng_), n(rng_)).normalized();
    std::uniform_real_distribution<double> u(-angle, angle);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = ExpSO3(u(rng_) * axis);
    T.translation() = Eigen::Vector3d(n(rng_), n(rng_), n(rng_)) * 3.0;
    return T;
  }
  std::vector<double> Params(const Eigen::Isometry3d& T) {
    std::vector<double> p(7);
    PoseToParameters(T, p.data());
    return p;
  }
  Eigen::Matrix<double, 6, 6> RandomInformation() {
    Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Random();
    return A * A.transpose() + 3.0 * Eigen::Matrix<double, 6, 6>::Identity();
  }
  std::mt19937 rng_{42};
  PoseManifold manifold_;
};

TEST_F(CostFunctionTest, RelativePose3dAnalyticMatchesNumeric) {
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Isometry3d Ti = RandomPose();
    // Near and far from the measurement: small and large errors.
    const Eigen::Isometry3d Tij = RandomPose();
    const Eigen::Isometry3d Tj =
        trial % 2 ? Eigen::Isometry3d(Ti * Tij * RandomPose(0.2)) : RandomPose();
    const RelativePose3dCost cost(Tij, RandomInformation());
    CheckJacobians(cost, {Params(Ti), Params(Tj)}, {&manifold_, &manifold_}, 1e-6);
  }
}

TEST_F(CostFunctionTest, PosePrior3dAnalyticMatchesNumeric) {
  for (int trial = 0; trial < 10; ++trial) {
    const PosePrior3dCost cost(RandomPose(), RandomInformation());
    CheckJacobians(cost, {Params(RandomPose())}, {&manifold_}, 1e-6);
  }
}

TEST_F(CostFunctionTest, ChordalPose3dAnalyticMatchesNumeric) {
  for (int trial = 0; trial < 20; ++trial) {
    const ChordalPose3dCost cost(RandomPose(), 7.0, 3.0);
    CheckJacobians(cost, {Params(RandomPose()), Params(RandomPose())}, {&manifold_, &manifold_},
                   1e-6);
  }
}

TEST_F(CostFunctionTest, RelativePose2dAnalyticMatchesNumeric) {
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::Matrix3d A = Eigen::Matrix3d::Random();
    const RelativePose2dCost cost(Eigen::Vector3d(u(rng_), u(rng_), u(rng_)),
                                  A * A.transpose() + Eigen::Matrix3d::Identity());
    CheckJacobians(cost, {{u(rng_), u(rng_), u(rng_)}, {u(rng_), u(rng_), u(rng_)}},
                   {nullptr, nullptr}, 1e-6);
  }
}

TEST_F(CostFunctionTest, ChordalPose2dAnalyticMatchesNumeric) {
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  for (int trial = 0; trial < 20; ++trial) {
    const ChordalPose2dCost cost(Eigen::Vector3d(u(rng_), u(rng_), u(rng_)), 5.0, 2.0);
    CheckJacobians(cost, {{u(rng_), u(rng_), u(rng_)}, {u(rng_), u(rng_), u(rng_)}},
                   {nullptr, nullptr}, 1e-6);
  }
}

TEST_F(CostFunctionTest, ManifoldPlusMinusRoundTrip) {
  const std::vector<double> x = Params(RandomPose());
  const double delta[6] = {0.1, -0.2, 0.3, 0.4, -0.5, 0.6};
  std::vector<double> y(7);
  double back[6];
  manifold_.Plus(x.data(), delta, y.data());
  manifold_.Minus(y.data(), x.data(), back);
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(back[k], delta[k], 1e-12);
}

}  // namespace
}  // namespace rover::mapping
