#include "mapping/graph/se_sync_certificate.h"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "mapping/graph/cholmod_llt.h"
#include "mapping/graph/graph_connectivity.h"
#include "mapping/graph/se_sync_objective.h"

namespace rover::mapping {

using SparseMatrix = Eigen::SparseMatrix<double>;
using Triplets = std::vector<Eigen::Triplet<double>>;

// Reports failure (not positive definite) through info(): the test.
struct SeSyncRelaxation::Factor {
  CholmodLlt llt;
};

namespace {

using Clock = std::chrono::steady_clock;

void AddBlock(Triplets& t, int row, int col, const Eigen::MatrixXd& block) {
  for (int r = 0; r < block.rows(); ++r) {
    for (int c = 0; c < block.cols(); ++c) {
      if (block(r, c) != 0.0) t.emplace_back(row + r, col + c, block(r, c));
    }
  }
}

// Orthonormal basis of the columns of Z (thin Householder QR).
Eigen::MatrixXd Orthonormalise(const Eigen::MatrixXd& Z) {
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(Z);
  return qr.householderQ() * Eigen::MatrixXd::Identity(Z.rows(), Z.cols());
}

}  // namespace

void SeSyncCertificateOptions::Validate() const {
  auto require = [](bool ok, const char* key, const std::string& expected) {
    if (!ok)
      throw std::invalid_argument(std::string("SeSyncCertificateOptions: ") + key + ": expected " +
                                  expected);
  };
  require(eigenvalue_tolerance > 0.0 && eigenvalue_tolerance < 1.0, "eigenvalue_tolerance",
          "a value in (0, 1)");
  require(residual_tolerance > 0.0 && residual_tolerance < 1.0, "residual_tolerance",
          "a value in (0, 1)");
  require(max_iterations >= 1, "max_iterations", "at least 1");
}

SeSyncRelaxation::SeSyncRelaxation(const PoseGraph& graph)
    : d_(graph.dimension), n_(static_cast<int>(graph.vertices.size())) {
  CheckGaugeAndFinite(graph);
  const auto index = VertexIndex(graph);
  const int dn = d_ * n_;
  Triplets rot;
  Triplets coupling;
  Triplets laplacian;
  rot.reserve(graph.edges.size() * 4 * static_cast<size_t>(d_ * d_));
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(d_, d_);
  for (const PoseEdge& e : graph.edges) {
    const IsotropicWeights w = SeSyncWeights(e, d_);
    const int i = index.at(e.from);
    const int j = index.at(e.to);
    const Eigen::MatrixXd R = e.measurement.linear().topLeftCorner(d_, d_);
    const Eigen::VectorXd t = e.measurement.translation().head(d_);
    AddBlock(rot, d_ * i, d_ * i, w.kappa * I + w.tau * t * t.transpose());
    AddBlock(rot, d_ * j, d_ * j, w.kappa * I);
    AddBlock(rot, d_ * i, d_ * j, -w.kappa * R);
    AddBlock(rot, d_ * j, d_ * i, -w.kappa * R.transpose());
    // V: rows are translations (vertex 0's removed: row k - 1 for vertex k).
    if (i > 0) AddBlock(coupling, i - 1, d_ * i, w.tau * t.transpose());
    if (j > 0) AddBlock(coupling, j - 1, d_ * i, -w.tau * t.transpose());
    if (i > 0) laplacian.emplace_back(i - 1, i - 1, w.tau);
    if (j > 0) laplacian.emplace_back(j - 1, j - 1, w.tau);
    if (i > 0 && j > 0) {
      laplacian.emplace_back(i - 1, j - 1, -w.tau);
      laplacian.emplace_back(j - 1, i - 1, -w.tau);
    }
  }
  rotation_block_.resize(dn, dn);
  rotation_block_.setFromTriplets(rot.begin(), rot.end());
  coupling_.resize(std::max(n_ - 1, 0), dn);
  coupling_.setFromTriplets(coupling.begin(), coupling.end());
  laplacian_.resize(std::max(n_ - 1, 0), std::max(n_ - 1, 0));
  laplacian_.setFromTriplets(laplacian.begin(), laplacian.end());
  laplacian_factor_ = std::make_unique<Factor>();
  if (n_ > 1) {
    laplacian_factor_->llt.compute(laplacian_);
    if (laplacian_factor_->llt.info() != Eigen::Success) {
      throw GraphError(graph.source +
                       ": SE-Sync certificate: expected a positive-definite reduced translation "
                       "Laplacian (connected graph, tau > 0), found a singular one");
    }
  }
}

SeSyncRelaxation::~SeSyncRelaxation() = default;

Eigen::MatrixXd SeSyncRelaxation::Rotations(const PoseGraph& graph) const {
  Eigen::MatrixXd Y(d_, d_ * n_);
  for (int k = 0; k < n_; ++k) {
    Y.middleCols(d_ * k, d_) =
        graph.vertices[static_cast<size_t>(k)].pose.linear().topLeftCorner(d_, d_);
  }
  return Y;
}

Eigen::MatrixXd SeSyncRelaxation::QProduct(const Eigen::MatrixXd& X) const {
  Eigen::MatrixXd out = rotation_block_ * X;
  if (n_ > 1) {
    const Eigen::MatrixXd VX = coupling_ * X;
    out -= coupling_.transpose() * laplacian_factor_->llt.solve(VX);
  }
  return out;
}

double SeSyncRelaxation::Objective(const Eigen::MatrixXd& Y) const {
  return (Y * QProduct(Y.transpose())).trace();
}

Eigen::MatrixXd SeSyncRelaxation::Translations(const Eigen::MatrixXd& Y,
                                               const Eigen::VectorXd& t0) const {
  // Stationarity in p: L p^T = -V Y^T, with p_0 = 0 (F is invariant under a
  // common shift), then shifted to t0.
  Eigen::MatrixXd p = Eigen::MatrixXd::Zero(Y.rows(), n_);
  if (n_ > 1) {
    const Eigen::MatrixXd rhs = -(coupling_ * Y.transpose());
    p.rightCols(n_ - 1) = laplacian_factor_->llt.solve(rhs).transpose();
  }
  return p.colwise() + t0;
}

Eigen::MatrixXd SeSyncRelaxation::LambdaBlocks(const Eigen::MatrixXd& Y,
                                               const Eigen::MatrixXd& QYt) const {
  Eigen::MatrixXd blocks(d_, d_ * n_);
  for (int i = 0; i < n_; ++i) {
    const Eigen::MatrixXd P = QYt.middleRows(d_ * i, d_) * Y.middleCols(d_ * i, d_);
    blocks.middleCols(d_ * i, d_) = 0.5 * (P + P.transpose());
  }
  return blocks;
}

SeSyncCertificate SeSyncRelaxation::Certify(const Eigen::MatrixXd& Y, double F_estimate,
                                            const SeSyncCertificateOptions& options) const {
  options.Validate();
  const Clock::time_point start = Clock::now();
  const int dn = d_ * n_;
  const int m = std::max(n_ - 1, 0);
  SeSyncCertificate out;
  out.rank = static_cast<int>(Y.rows());
  if (Y.cols() != dn) {
    throw std::invalid_argument("SeSyncRelaxation::Certify: expected Y with " + std::to_string(dn) +
                                " columns, found " + std::to_string(Y.cols()));
  }
  if (n_ <= 1) {  // Nothing relative to certify: one pose is its own optimum.
    out.certified = true;
    out.min_eigenvector = Eigen::VectorXd::Zero(dn);
    return out;
  }
  const Eigen::MatrixXd QYt = QProduct(Y.transpose());
  const Eigen::MatrixXd lambda = LambdaBlocks(Y, QYt);
  for (int i = 0; i < n_; ++i) out.relaxation_value += lambda.middleCols(d_ * i, d_).trace();
  // Lambda X for X with dn rows.
  auto lambda_times = [&](const Eigen::MatrixXd& X) -> Eigen::MatrixXd {
    Eigen::MatrixXd out_x(X.rows(), X.cols());
    for (int i = 0; i < n_; ++i) {
      out_x.middleRows(d_ * i, d_) = lambda.middleCols(d_ * i, d_) * X.middleRows(d_ * i, d_);
    }
    return out_x;
  };
  auto s_times = [&](const Eigen::MatrixXd& X) -> Eigen::MatrixXd {
    return QProduct(X) - lambda_times(X);
  };
  out.gradient_norm = (QYt - lambda_times(Y.transpose())).norm();
  out.eta = options.eigenvalue_tolerance * rotation_block_.diagonal().maxCoeff();

  // K(sigma) without sigma: [L_r V_r; V_r^T A - Lambda].
  Triplets t;
  t.reserve(static_cast<size_t>(laplacian_.nonZeros() + 2 * coupling_.nonZeros() +
                                rotation_block_.nonZeros() + dn * d_));
  for (int c = 0; c < laplacian_.outerSize(); ++c) {
    for (SparseMatrix::InnerIterator it(laplacian_, c); it; ++it) {
      t.emplace_back(it.row(), it.col(), it.value());
    }
  }
  for (int c = 0; c < coupling_.outerSize(); ++c) {
    for (SparseMatrix::InnerIterator it(coupling_, c); it; ++it) {
      t.emplace_back(it.row(), m + it.col(), it.value());
      t.emplace_back(m + it.col(), it.row(), it.value());
    }
  }
  for (int c = 0; c < rotation_block_.outerSize(); ++c) {
    for (SparseMatrix::InnerIterator it(rotation_block_, c); it; ++it) {
      t.emplace_back(m + it.row(), m + it.col(), it.value());
    }
  }
  for (int i = 0; i < n_; ++i) {
    for (int r = 0; r < d_; ++r) {
      for (int c = 0; c < d_; ++c) {
        t.emplace_back(m + d_ * i + r, m + d_ * i + c, -lambda(r, d_ * i + c));
      }
    }
  }
  SparseMatrix K0(m + dn, m + dn);
  K0.setFromTriplets(t.begin(), t.end());
  Factor factor;
  factor.llt.analyzePattern(K0);
  auto positive_definite_at = [&](double sigma) {
    SparseMatrix K = K0;
    for (int k = m; k < m + dn; ++k) K.coeffRef(k, k) += sigma;
    factor.llt.factorize(K);
    ++out.factorisations;
    return factor.llt.info() == Eigen::Success;
  };

  // The test: S + eta I > 0. If it fails, raise the shift until K(sigma) is
  // positive definite: the inverse iteration needs a definite shifted S.
  double sigma = out.eta;
  out.certified = positive_definite_at(sigma);
  // Not certified: lambda_min(S) <= -sigma_fail for the largest shift at
  // which K was indefinite; the iteration must reach that far down.
  double sigma_fail = 0.0;
  for (int k = 0; !out.certified && k < 60; ++k) {
    sigma_fail = sigma;
    sigma *= 10.0;
    if (positive_definite_at(sigma)) break;
  }
  out.lambda_lower = -sigma;

  // Shifted inverse subspace iteration with Rayleigh-Ritz on S. The rows of Y
  // start the block: at a certified critical point they span the null space
  // of S (its minimum); otherwise they are unstable and a random part leaves
  // them.
  const int block = std::min(static_cast<int>(Y.rows()) + 2, dn);
  Eigen::MatrixXd X(dn, block);
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> normal;
  for (int c = 0; c < block; ++c) {
    if (c < Y.rows()) {
      X.col(c) = Y.row(c).transpose();
    } else {
      for (int k = 0; k < dn; ++k) X(k, c) = normal(rng);
    }
  }
  X = Orthonormalise(X);
  Eigen::VectorXd theta = Eigen::VectorXd::Zero(block);
  double residual = 0.0;
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(m + dn, block);
  for (out.iterations = 0; out.iterations < options.max_iterations;) {
    rhs.bottomRows(dn) = X;
    const Eigen::MatrixXd Z = Orthonormalise(factor.llt.solve(rhs).bottomRows(dn));
    ++out.iterations;
    const Eigen::MatrixXd SZ = s_times(Z);
    const Eigen::MatrixXd T = Z.transpose() * SZ;
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(0.5 * (T + T.transpose()));
    theta = eig.eigenvalues();
    X = Z * eig.eigenvectors();
    residual = (SZ * eig.eigenvectors().col(0) - theta(0) * X.col(0)).norm();
    // Converged: theta(0) is within the residual of an eigenvalue, and (if
    // not certified) low enough to be the negative one, not the null space
    // of S that the rows of Y span.
    const bool low_enough = out.certified || theta(0) <= -sigma_fail + residual;
    if (low_enough && residual <= options.residual_tolerance * std::abs(theta(0)) + out.eta) {
      break;
    }
    // Not certified: move the shift towards the estimate (never past the
    // true minimum: then K is indefinite and the old shift is restored).
    if (!out.certified && theta(0) < 0.0 && out.iterations % 3 == 0) {
      const double closer = -theta(0) + 0.1 * (sigma + theta(0));
      if (closer < sigma && positive_definite_at(closer)) {
        sigma = closer;
        out.lambda_lower = -sigma;
      } else if (closer < sigma) {
        sigma_fail = std::max(sigma_fail, closer);
        (void)positive_definite_at(sigma);
      }
    }
  }
  out.lambda_min = theta(0);
  out.min_eigenvector = X.col(0).normalized();
  if (out.certified) {
    // Lambda itself is dual feasible (to the tolerance eta): SE-Sync's bound.
    out.dual_bound = out.relaxation_value;
  } else {
    // A proved bound: tighten lambda_lower to the estimate minus its
    // residual with one more factorisation, then Lambda + lambda_lower I is
    // dual feasible.
    const double tighter = -(theta(0) - residual);
    if (tighter > 0.0 && tighter < sigma && positive_definite_at(tighter)) {
      out.lambda_lower = -tighter;
    }
    out.dual_bound = out.relaxation_value + static_cast<double>(dn) * out.lambda_lower;
  }
  out.suboptimality_bound = F_estimate - out.dual_bound;
  out.time_s = std::chrono::duration<double>(Clock::now() - start).count();
  return out;
}

SeSyncCertificate CertifySeSync(const PoseGraph& graph, const SeSyncCertificateOptions& options) {
  const Clock::time_point start = Clock::now();
  const SeSyncRelaxation relaxation(graph);
  SeSyncCertificate c =
      relaxation.Certify(relaxation.Rotations(graph), SeSyncObjective(graph), options);
  c.time_s = std::chrono::duration<double>(Clock::now() - start).count();
  return c;
}

}  // namespace rover::mapping
