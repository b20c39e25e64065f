#include "mapping/graph/se_sync_newton_solver.h"

#include <ceres/cost_function.h>

#include <Eigen/SparseCore>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>

#include "mapping/graph/cholmod_llt.h"
#include "mapping/graph/chordal_pose_2d_cost.h"
#include "mapping/graph/chordal_pose_3d_cost.h"
#include "mapping/graph/graph_connectivity.h"
#include "mapping/graph/pose_manifold.h"
#include "mapping/graph/relative_pose_2d_cost.h"
#include "mapping/graph/se_sync_objective.h"

namespace rover::mapping {
namespace {

using Clock = std::chrono::steady_clock;
using SparseMatrix = Eigen::SparseMatrix<double>;
using Residual = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 12, 1>;

// A symmetric block-sparse matrix with a fixed pattern of p x p blocks: full
// diagonal blocks and the lower off-diagonal blocks (row block > column
// block), stored column-major so CHOLMOD (lower triangle) and
// selfadjointView<Lower> read it as is. Values are written through the
// precomputed position of each block's top row in each of its columns.
class BlockSymmetricMatrix {
 public:
  BlockSymmetricMatrix(int num_blocks, int p, const std::vector<std::pair<int, int>>& lower)
      : p_(p) {
    std::vector<Eigen::Triplet<double>> t;
    std::vector<std::pair<int, int>> blocks;
    for (int b = 0; b < num_blocks; ++b) blocks.emplace_back(b, b);
    blocks.insert(blocks.end(), lower.begin(), lower.end());
    t.reserve(blocks.size() * static_cast<size_t>(p * p));
    for (const auto& [I, J] : blocks) {
      for (int c = 0; c < p; ++c) {
        for (int r = 0; r < p; ++r) t.emplace_back(p * I + r, p * J + c, 0.0);
      }
    }
    matrix_.resize(num_blocks * p, num_blocks * p);
    matrix_.setFromTriplets(t.begin(), t.end());
    matrix_.makeCompressed();
    positions_.resize(blocks.size() * static_cast<size_t>(p));
    const int* outer = matrix_.outerIndexPtr();
    const int* inner = matrix_.innerIndexPtr();
    for (size_t k = 0; k < blocks.size(); ++k) {
      const auto [I, J] = blocks[k];
      for (int c = 0; c < p; ++c) {
        const int col = p * J + c;
        const int* at = std::lower_bound(inner + outer[col], inner + outer[col + 1], p * I);
        positions_[k * static_cast<size_t>(p) + static_cast<size_t>(c)] =
            static_cast<int>(at - inner);
      }
    }
  }

  // Block index of diagonal block I: I; of the k-th lower block: num_blocks + k.
  template <typename Block>
  void Add(int block, const Block& M) {
    double* values = matrix_.valuePtr();
    for (int c = 0; c < p_; ++c) {
      const int base = positions_[static_cast<size_t>(block * p_ + c)];
      for (int r = 0; r < p_; ++r) values[base + r] += M(r, c);
    }
  }

  // Value index of the diagonal entry k (in diagonal block k / p).
  int DiagonalPosition(int k) const {
    return positions_[static_cast<size_t>((k / p_) * p_ + k % p_)] + k % p_;
  }

  void SetZero() { std::fill_n(matrix_.valuePtr(), matrix_.nonZeros(), 0.0); }
  SparseMatrix& matrix() { return matrix_; }

 private:
  int p_;
  SparseMatrix matrix_;
  std::vector<int> positions_;
};

struct EdgeData {
  int i = 0;  // Vertex indices.
  int j = 0;
  int block = -1;  // Lower block of (i, j) if both vary, else -1.
  double kappa = 0.0;
  double tau = 0.0;
  Eigen::Matrix3d R;  // Measured rotation (2D: about z).
  Eigen::Vector3d t;  // Measured translation (2D: z = 0).
  std::unique_ptr<ceres::CostFunction> cost;
};

class NewtonProblem {
 public:
  explicit NewtonProblem(const PoseGraph& graph)
      : planar_(graph.dimension == 2),
        n_(static_cast<int>(graph.vertices.size())),
        stride_(planar_ ? 3 : 7),
        p_(planar_ ? 3 : 6),
        residuals_(planar_ ? 4 : 12) {
    const auto index = VertexIndex(graph);
    std::map<std::pair<int, int>, int> lower_index;
    std::vector<std::pair<int, int>> lower;
    for (const PoseEdge& e : graph.edges) {
      EdgeData d;
      d.i = index.at(e.from);
      d.j = index.at(e.to);
      const IsotropicWeights w = SeSyncWeights(e, graph.dimension);
      d.kappa = w.kappa;
      d.tau = w.tau;
      d.R = e.measurement.linear();
      d.t = e.measurement.translation();
      if (planar_) {
        d.cost = std::make_unique<ChordalPose2dCost>(PlanarPose(e.measurement), w.kappa, w.tau);
      } else {
        d.cost = std::make_unique<ChordalPose3dCost>(e.measurement, w.kappa, w.tau);
      }
      if (d.i > 0 && d.j > 0) {
        const std::pair<int, int> key(std::max(d.i, d.j) - 1, std::min(d.i, d.j) - 1);
        auto [it, inserted] = lower_index.emplace(key, static_cast<int>(lower.size()));
        if (inserted) lower.push_back(key);
        d.block = n_ - 1 + it->second;
      }
      edges_.push_back(std::move(d));
    }
    hessian_ = std::make_unique<BlockSymmetricMatrix>(n_ - 1, p_, lower);
    x_.resize(static_cast<size_t>(n_ * stride_));
    for (int k = 0; k < n_; ++k) {
      const Eigen::Isometry3d& T = graph.vertices[static_cast<size_t>(k)].pose;
      if (planar_) {
        const Eigen::Vector3d q = PlanarPose(T);
        std::copy(q.data(), q.data() + 3, x_.data() + k * stride_);
      } else {
        PoseToParameters(T, x_.data() + k * stride_);
      }
    }
  }

  int size() const { return (n_ - 1) * p_; }
  const std::vector<double>& x() const { return x_; }
  void set_x(std::vector<double> x) { x_ = std::move(x); }
  SparseMatrix& hessian() { return hessian_->matrix(); }
  const Eigen::VectorXd& gradient() const { return gradient_; }
  const Eigen::VectorXd& gauss_newton_diagonal() const { return gn_diagonal_; }
  int DiagonalPosition(int k) const { return hessian_->DiagonalPosition(k); }

  // F/2 at x.
  double Cost(const std::vector<double>& x) const {
    double cost = 0.0;
    Residual r(residuals_);
    for (const EdgeData& e : edges_) {
      const double* blocks[2] = {x.data() + e.i * stride_, x.data() + e.j * stride_};
      e.cost->Evaluate(blocks, r.data(), nullptr);
      cost += 0.5 * r.squaredNorm();
    }
    return cost;
  }

  // F/2, its gradient and Hessian (tangent coordinates of vertices 1..n-1)
  // at the current x: exact if `exact`, else Gauss-Newton's J^T J.
  double Linearise(bool exact) {
    hessian_->SetZero();
    gradient_ = Eigen::VectorXd::Zero(size());
    std::vector<Eigen::Matrix3d> R(static_cast<size_t>(n_));
    std::vector<Eigen::Vector3d> t(static_cast<size_t>(n_));
    for (int k = 0; k < n_; ++k) {
      const double* b = x_.data() + k * stride_;
      if (planar_) {
        R[static_cast<size_t>(k)] =
            Eigen::AngleAxisd(b[2], Eigen::Vector3d::UnitZ()).toRotationMatrix();
        t[static_cast<size_t>(k)] = Eigen::Vector3d(b[0], b[1], 0.0);
      } else {
        const Eigen::Isometry3d T = PoseFromParameters(b);
        R[static_cast<size_t>(k)] = T.linear();
        t[static_cast<size_t>(k)] = T.translation();
      }
    }
    // Euclidean gradient of F/2 with respect to each R_i (curvature term).
    std::vector<Eigen::Matrix3d> G(static_cast<size_t>(n_), Eigen::Matrix3d::Zero());
    const double cost =
        planar_ ? AccumulateEdges<4, 3, 3>(R, t, G) : AccumulateEdges<12, 6, 7>(R, t, G);
    gn_diagonal_.resize(size());
    for (int k = 0; k < size(); ++k) gn_diagonal_(k) = hessian().valuePtr()[DiagonalPosition(k)];
    if (!exact) return cost;
    // Curvature of the retraction: C_i = Lambda_i - tr(Lambda_i) I.
    Eigen::MatrixXd C = Eigen::MatrixXd::Zero(p_, p_);
    for (int k = 1; k < n_; ++k) {
      const auto sk = static_cast<size_t>(k);
      const Eigen::Matrix3d P = R[sk].transpose() * G[sk];
      const Eigen::Matrix3d lambda = 0.5 * (P + P.transpose());
      const Eigen::Matrix3d Ck = lambda - lambda.trace() * Eigen::Matrix3d::Identity();
      if (planar_) {
        C(2, 2) = Ck(2, 2);
      } else {
        C.bottomRightCorner<3, 3>() = Ck;
      }
      hessian_->Add(k - 1, C);
    }
    return cost;
  }

  // Adds every edge's J^T J blocks and J^T r to the Hessian and gradient and
  // its Euclidean rotation gradients to G; returns F/2. Fixed sizes (M
  // residuals, P tangent, A ambient parameters): dynamic-size products of
  // these small blocks would go through Eigen's GEMM and dominate the time.
  template <int M, int P, int A>
  double AccumulateEdges(const std::vector<Eigen::Matrix3d>& R,
                         const std::vector<Eigen::Vector3d>& t, std::vector<Eigen::Matrix3d>& G) {
    Eigen::Matrix<double, M, 1> r;
    Eigen::Matrix<double, M, A, Eigen::RowMajor> Ji;
    Eigen::Matrix<double, M, A, Eigen::RowMajor> Jj;
    double* jacobians[2] = {Ji.data(), Jj.data()};
    double cost = 0.0;
    for (const EdgeData& e : edges_) {
      const double* blocks[2] = {x_.data() + e.i * stride_, x_.data() + e.j * stride_};
      e.cost->Evaluate(blocks, r.data(), jacobians);
      cost += 0.5 * r.squaredNorm();
      const Eigen::Matrix<double, M, P> Ai = Ji.template leftCols<P>();
      const Eigen::Matrix<double, M, P> Aj = Jj.template leftCols<P>();
      const int a = e.i - 1;
      const int b = e.j - 1;
      if (a >= 0) {
        hessian_->Add(a, Eigen::Matrix<double, P, P>(Ai.transpose() * Ai));
        gradient_.segment<P>(a * P) += Ai.transpose() * r;
      }
      if (b >= 0) {
        hessian_->Add(b, Eigen::Matrix<double, P, P>(Aj.transpose() * Aj));
        gradient_.segment<P>(b * P) += Aj.transpose() * r;
      }
      if (e.block >= 0) {
        hessian_->Add(e.block, a > b ? Eigen::Matrix<double, P, P>(Ai.transpose() * Aj)
                                     : Eigen::Matrix<double, P, P>(Aj.transpose() * Ai));
      }
      const auto si = static_cast<size_t>(e.i);
      const auto sj = static_cast<size_t>(e.j);
      const Eigen::Matrix3d E = R[sj] - R[si] * e.R;
      const Eigen::Vector3d et = t[sj] - t[si] - R[si] * e.t;
      G[si] -= e.kappa * E * e.R.transpose() + e.tau * et * e.t.transpose();
      G[sj] += e.kappa * E;
    }
    return cost;
  }

  // x (+) delta for the variables of vertices 1..n-1.
  std::vector<double> Plus(const Eigen::VectorXd& delta) const {
    std::vector<double> out = x_;
    const PoseManifold manifold;
    for (int k = 1; k < n_; ++k) {
      const double* d = delta.data() + (k - 1) * p_;
      double* b = out.data() + k * stride_;
      if (planar_) {
        for (int c = 0; c < 3; ++c) b[c] += d[c];
      } else {
        manifold.Plus(x_.data() + k * stride_, d, b);
      }
    }
    return out;
  }

  void WriteTo(PoseGraph& graph) const {
    for (int k = 0; k < n_; ++k) {
      const double* b = x_.data() + k * stride_;
      graph.vertices[static_cast<size_t>(k)].pose =
          planar_ ? PoseFromPlanar(b[0], b[1], WrapAngle(b[2])) : PoseFromParameters(b);
    }
  }

 private:
  bool planar_;
  int n_;
  int stride_;
  int p_;
  int residuals_;
  std::vector<EdgeData> edges_;
  std::unique_ptr<BlockSymmetricMatrix> hessian_;
  std::vector<double> x_;
  Eigen::VectorXd gradient_;
  Eigen::VectorXd gn_diagonal_;
};

}  // namespace

void SeSyncNewtonOptions::Validate() const {
  auto require = [](bool ok, const char* key, const char* expected) {
    if (!ok) {
      throw std::invalid_argument(std::string("SeSyncNewtonOptions: ") + key + ": expected " +
                                  expected);
    }
  };
  require(max_iterations >= 1, "max_iterations", "at least 1");
  require(function_tolerance >= 0.0 && function_tolerance < 1.0, "function_tolerance",
          "a value in [0, 1)");
  require(gradient_tolerance >= 0.0, "gradient_tolerance", "a value >= 0");
  require(gauss_newton_steps >= 0, "gauss_newton_steps", "a value >= 0");
}

SeSyncQuadraticModel SeSyncNewtonModel(const PoseGraph& graph, bool exact) {
  CheckGaugeAndFinite(graph);
  SeSyncQuadraticModel model;
  if (graph.vertices.size() < 2) return model;
  NewtonProblem problem(graph);
  model.cost = problem.Linearise(exact);
  model.gradient = problem.gradient();
  model.hessian = problem.hessian();
  return model;
}

SeSyncNewtonSummary SolveSeSyncNewton(PoseGraph& graph, const SeSyncNewtonOptions& options) {
  options.Validate();
  CheckGaugeAndFinite(graph);
  const Clock::time_point start = Clock::now();
  SeSyncNewtonSummary out;
  if (graph.vertices.size() < 2) {
    out.converged = true;
    out.message = "nothing to optimise (one vertex)";
    return out;
  }
  NewtonProblem problem(graph);
  // Far from the optimum (the chordal start) the exact Hessian may be
  // indefinite and Gauss-Newton is the better model.
  bool exact = options.gauss_newton_steps == 0;
  double cost = problem.Linearise(exact);
  out.initial_cost = cost;
  out.final_cost = cost;
  SparseMatrix A = problem.hessian();
  CholmodLlt llt;  // Fails on an indefinite Hessian: that raises the damping.
  llt.analyzePattern(A);
  // Levenberg-Marquardt damping relative to diag(J^T J); 0: pure Newton.
  double mu = 0.0;
  out.message = "max_iterations reached";
  while (out.iterations < options.max_iterations) {
    out.gradient_max_norm = problem.gradient().lpNorm<Eigen::Infinity>();
    if (out.gradient_max_norm <= options.gradient_tolerance) {
      out.converged = true;
      out.message = "gradient tolerance reached";
      break;
    }
    bool accepted = false;
    double new_cost = cost;
    bool at_optimum = false;
    for (int attempt = 0; attempt < 60 && !accepted && !at_optimum; ++attempt) {
      A = problem.hessian();
      for (int k = 0; k < problem.size(); ++k) {
        A.valuePtr()[problem.DiagonalPosition(k)] +=
            mu * std::max(problem.gauss_newton_diagonal()(k), 1e-12);
      }
      llt.factorize(A);
      ++out.factorisations;
      if (llt.info() != Eigen::Success) {  // Hessian indefinite here: damp.
        mu = mu == 0.0 ? 1e-6 : mu * 10.0;
        continue;
      }
      const Eigen::VectorXd delta = -llt.solve(problem.gradient());
      const Eigen::VectorXd H_delta = problem.hessian().selfadjointView<Eigen::Lower>() * delta;
      const double predicted = -(problem.gradient().dot(delta) + 0.5 * delta.dot(H_delta));
      if (mu == 0.0 && predicted >= 0.0 && predicted <= 0.5 * options.function_tolerance * cost) {
        // The Newton step would gain less than the tolerance (and F at this
        // precision is round-off): converged where we are.
        at_optimum = true;
        break;
      }
      std::vector<double> x = problem.Plus(delta);
      new_cost = problem.Cost(x);
      const double rho = (cost - new_cost) / predicted;
      if (predicted > 0.0 && rho > 0.0) {
        accepted = true;
        problem.set_x(std::move(x));
        // A good model: relax the damping fast (back to pure Newton steps,
        // which the ill-conditioned directions of some graphs need).
        if (rho > 0.75) mu = mu < 1e-10 ? 0.0 : mu / 10.0;
        continue;
      }
      if (predicted >= 0.0 && predicted <= 0.5 * options.function_tolerance * cost) {
        // Rejected, and the model gains nothing measurable: F is at its
        // round-off floor.
        at_optimum = true;
        continue;
      }
      // The full step overshoots where the quadratic model fails (a weak,
      // curved direction). The step is still a descent direction (A is
      // positive definite): backtrack along it, which costs evaluations of F
      // only, before raising the damping (a factorisation each).
      const double slope = problem.gradient().dot(delta);  // < 0.
      for (double alpha = 0.5; alpha >= 1.0 / 64.0 && !accepted; alpha *= 0.5) {
        x = problem.Plus(alpha * delta);
        new_cost = problem.Cost(x);
        if (new_cost <= cost + 1e-4 * alpha * slope) {
          accepted = true;
          problem.set_x(std::move(x));
        }
      }
      if (!accepted) mu = mu == 0.0 ? 1e-6 : mu * 10.0;
    }
    if (at_optimum) {
      out.converged = true;
      out.message = "Newton decrement below the function tolerance";
      break;
    }
    if (!accepted) {
      out.message = "no step decreases F (damping exhausted)";
      break;
    }
    ++out.iterations;
    const double decrease = cost - new_cost;
    exact = out.iterations >= options.gauss_newton_steps;
    cost = problem.Linearise(exact);
    out.final_cost = cost;
    if (options.progress) {
      options.progress(out.iterations, cost,
                       std::chrono::duration<double>(Clock::now() - start).count());
    }
    if (decrease <= options.function_tolerance * (cost + decrease)) {
      out.converged = true;
      out.message = "function tolerance reached";
      out.gradient_max_norm = problem.gradient().lpNorm<Eigen::Infinity>();
      break;
    }
  }
  problem.WriteTo(graph);
  return out;
}

}  // namespace rover::mapping
