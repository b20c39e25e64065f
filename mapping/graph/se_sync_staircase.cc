#include "mapping/graph/se_sync_staircase.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <cmath>
#include <stdexcept>
#include <string>

namespace rover::mapping {
namespace {

// Polar retraction of every r x d block of Y + step onto the Stiefel manifold.
Eigen::MatrixXd Retract(const Eigen::MatrixXd& Y, const Eigen::MatrixXd& step, int d) {
  Eigen::MatrixXd out(Y.rows(), Y.cols());
  for (int i = 0; i < Y.cols() / d; ++i) {
    const Eigen::MatrixXd M = Y.middleCols(d * i, d) + step.middleCols(d * i, d);
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(M, Eigen::ComputeThinU | Eigen::ComputeThinV);
    out.middleCols(d * i, d) = svd.matrixU() * svd.matrixV().transpose();
  }
  return out;
}

// f(Y) = tr(Y Q Y^T) and its Riemannian gradient on St(d, r)^n.
double ObjectiveAndGradient(const SeSyncRelaxation& relaxation, const Eigen::MatrixXd& Y,
                            Eigen::MatrixXd& gradient) {
  const int d = relaxation.dimension();
  const Eigen::MatrixXd QYt = relaxation.QProduct(Y.transpose());
  const Eigen::MatrixXd G = 2.0 * QYt.transpose();
  gradient.resize(Y.rows(), Y.cols());
  for (int i = 0; i < relaxation.num_poses(); ++i) {
    const auto Yi = Y.middleCols(d * i, d);
    const Eigen::MatrixXd P = Yi.transpose() * G.middleCols(d * i, d);
    gradient.middleCols(d * i, d) = G.middleCols(d * i, d) - Yi * (0.5 * (P + P.transpose()));
  }
  return (Y * QYt).trace();
}

// Riemannian gradient descent at the rank of Y: Barzilai-Borwein step,
// Armijo backtracking. Returns the steps taken.
int Descend(const SeSyncRelaxation& relaxation, Eigen::MatrixXd& Y,
            const SeSyncStaircaseOptions& options, double step0) {
  const int d = relaxation.dimension();
  Eigen::MatrixXd g;
  double f = ObjectiveAndGradient(relaxation, Y, g);
  const double stop = options.relative_gradient_tolerance * g.norm();
  double alpha = step0;
  int k = 0;
  for (; k < options.max_iterations && g.norm() > stop; ++k) {
    Eigen::MatrixXd Y_new;
    Eigen::MatrixXd g_new;
    double f_new = f;
    bool ok = false;
    for (int halvings = 0; halvings < 40 && !ok; ++halvings, alpha *= 0.5) {
      Y_new = Retract(Y, -alpha * g, d);
      f_new = ObjectiveAndGradient(relaxation, Y_new, g_new);
      ok = f_new <= f - 1e-4 * alpha * g.squaredNorm();
      if (ok) break;
    }
    if (!ok) break;  // No decrease at any step: stationary to round-off.
    const Eigen::MatrixXd s = Y_new - Y;
    const Eigen::MatrixXd y = g_new - g;
    const double sy = std::abs((s.array() * y.array()).sum());
    alpha = sy > 0.0 ? s.squaredNorm() / sy : 2.0 * alpha;
    Y = std::move(Y_new);
    g = std::move(g_new);
    f = f_new;
  }
  return k;
}

// SE-Sync's rounding of Y (r x dn) to SO(d)^n.
Eigen::MatrixXd Round(const Eigen::MatrixXd& Y, int d) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Y * Y.transpose());
  // Top-d eigenvectors of Y Y^T (ascending order: the last d).
  Eigen::MatrixXd R = eig.eigenvectors().rightCols(d).transpose() * Y;
  const int n = static_cast<int>(Y.cols()) / d;
  int positive = 0;
  for (int i = 0; i < n; ++i) positive += R.middleCols(d * i, d).determinant() > 0.0 ? 1 : 0;
  if (2 * positive < n) R.row(d - 1) *= -1.0;
  for (int i = 0; i < n; ++i) {
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(R.middleCols(d * i, d),
                                                Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::MatrixXd D = Eigen::MatrixXd::Identity(d, d);
    D(d - 1, d - 1) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
    R.middleCols(d * i, d) = svd.matrixU() * D * svd.matrixV().transpose();
  }
  return R;
}

}  // namespace

void SeSyncStaircaseOptions::Validate() const {
  auto require = [](bool ok, const char* key, const char* expected) {
    if (!ok) {
      throw std::invalid_argument(std::string("SeSyncStaircaseOptions: ") + key + ": expected " +
                                  expected);
    }
  };
  require(max_rank >= 0, "max_rank", "0 (d + 3) or a rank above d");
  require(max_iterations >= 1, "max_iterations", "at least 1");
  require(relative_gradient_tolerance > 0.0 && relative_gradient_tolerance < 1.0,
          "relative_gradient_tolerance", "a value in (0, 1)");
  certificate.Validate();
}

SeSyncStaircaseSummary ClimbSeSyncStaircase(PoseGraph& graph, const SeSyncCertificate& start,
                                            const SeSyncStaircaseOptions& options) {
  options.Validate();
  const SeSyncRelaxation relaxation(graph);
  const int d = relaxation.dimension();
  const int n = relaxation.num_poses();
  const int max_rank = options.max_rank > 0 ? options.max_rank : d + 3;
  SeSyncStaircaseSummary out;
  Eigen::MatrixXd Y = relaxation.Rotations(graph);
  const Eigen::MatrixXd R0 = Y.leftCols(d);
  SeSyncCertificate certificate = start;
  out.message = "max rank reached";
  while (!certificate.certified && Y.rows() < max_rank) {
    // Saddle escape: one rank up along the negative-curvature direction.
    const auto r = Y.rows() + 1;
    Eigen::MatrixXd lifted = Eigen::MatrixXd::Zero(r, Y.cols());
    lifted.topRows(Y.rows()) = Y;
    Eigen::MatrixXd direction = Eigen::MatrixXd::Zero(r, Y.cols());
    direction.row(r - 1) = certificate.min_eigenvector.transpose();
    const double f0 = relaxation.Objective(lifted);
    Eigen::MatrixXd escaped;
    bool escaped_ok = false;
    for (double alpha = std::sqrt(static_cast<double>(n)); alpha > 1e-12 && !escaped_ok;
         alpha *= 0.5) {
      escaped = Retract(lifted, alpha * direction, d);
      escaped_ok = relaxation.Objective(escaped) < f0 - 1e-12 * std::abs(f0);
    }
    if (!escaped_ok) {
      out.message = "saddle escape found no decrease";
      break;
    }
    Y = std::move(escaped);
    out.iterations += Descend(relaxation, Y, options, 1e-3);
    out.rank = static_cast<int>(Y.rows());
    certificate = relaxation.Certify(Y, relaxation.Objective(Y), options.certificate);
    out.relaxation_value = certificate.relaxation_value;
    if (certificate.certified) out.message = "certified at rank " + std::to_string(out.rank);
  }
  out.certified = certificate.certified;
  // Round to SO(d)^n, re-anchor vertex 0's rotation (F is invariant under a
  // common rotation), translations optimal with vertex 0's kept.
  Eigen::MatrixXd R = Round(Y, d);
  const Eigen::MatrixXd G = R0 * R.leftCols(d).transpose();
  R = G * R;
  const Eigen::VectorXd t0 = graph.vertices[0].pose.translation().head(d);
  const Eigen::MatrixXd t = relaxation.Translations(R, t0);
  for (int i = 0; i < n; ++i) {
    Eigen::Isometry3d& T = graph.vertices[static_cast<size_t>(i)].pose;
    T.linear().setIdentity();
    T.linear().topLeftCorner(d, d) = R.middleCols(d * i, d);
    T.translation().setZero();
    T.translation().head(d) = t.col(i);
  }
  return out;
}

}  // namespace rover::mapping
