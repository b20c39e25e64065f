#include "mapping/graph/incremental_pose_solver.h"

#include <Eigen/Cholesky>
#include <Eigen/OrderingMethods>
#include <Eigen/SparseCore>
#include <algorithm>
#include <map>
#include <queue>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>

#include "mapping/graph/pose_manifold.h"
#include "mapping/graph/relative_pose_3d_cost.h"

namespace rover::mapping {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;
using RowJacobian = Eigen::Matrix<double, 6, 7, Eigen::RowMajor>;

// A vector indexed by the solver's int variable / position / factor indices.
template <class T>
struct IVec : std::vector<T> {
  using Base = std::vector<T>;
  using Base::Base;
  explicit IVec(int n) : Base(static_cast<size_t>(n)) {}
  IVec(int n, const T& value) : Base(static_cast<size_t>(n), value) {}
  void assign(int n, const T& value) { Base::assign(static_cast<size_t>(n), value); }
  void reserve(int n) { Base::reserve(static_cast<size_t>(n)); }
  T& operator[](int i) { return Base::operator[](static_cast<size_t>(i)); }
  const T& operator[](int i) const { return Base::operator[](static_cast<size_t>(i)); }
  T& operator[](size_t i) { return Base::operator[](i); }
  const T& operator[](size_t i) const { return Base::operator[](i); }
};

double MaxStep(const Vector6d& d) { return d.cwiseAbs().maxCoeff(); }

}  // namespace

class IncrementalPoseSolver::Impl {
 public:
  explicit Impl(const IncrementalPoseSolverOptions& options) : options_(options) {}

  struct Variable {
    std::array<double, 7> theta{};
    Vector6d delta = Vector6d::Zero();
    IVec<int> factors;
    IVec<int> neighbours;  // sorted, unique
  };

  struct Factor {
    int a = -1;
    int b = -1;  // -1: prior
    std::unique_ptr<RelativePose3dCost> between;
    std::unique_ptr<PosePrior3dCost> prior;
    bool robust = false;
    // Whitened (and IRLS-weighted) linearisation at theta.
    Matrix6d J_a = Matrix6d::Zero();
    Matrix6d J_b = Matrix6d::Zero();
    Vector6d r = Vector6d::Zero();
    // Model Hessian weight: the factor adds J^T M J to H and -rho' J^T r to b.
    Matrix6d M = Matrix6d::Identity();
    double rho1 = 1.0;
  };

  // Linearises factor k at the theta of its variables; returns false if the
  // cost function fails (never for these residuals).
  void Linearize(int k) {
    Factor& f = factors_[k];
    RowJacobian Ja, Jb;
    Vector6d r;
    if (f.b < 0) {
      const double* params[1] = {variables_[f.a].theta.data()};
      double* jac[1] = {Ja.data()};
      f.prior->Evaluate(params, r.data(), jac);
      Jb.setZero();
    } else {
      const double* params[2] = {variables_[f.a].theta.data(), variables_[f.b].theta.data()};
      double* jac[2] = {Ja.data(), Jb.data()};
      f.between->Evaluate(params, r.data(), jac);
    }
    const double s = r.squaredNorm();
    f.J_a = Ja.leftCols<6>();
    f.J_b = Jb.leftCols<6>();
    f.r = r;
    if (!f.robust) {
      f.M.setIdentity();
      f.rho1 = 1.0;
      return;
    }
    // Cauchy: the Hessian of 1/2 rho(|r|^2) is J^T (rho' I + 2 rho'' r r^T) J.
    // Plain reweighting (rho' J^T J) drops the second term and converges only
    // linearly (inlier loop closures sit near u = s / c^2 ~ 1, where rho'
    // changes fast); the term is kept: along r the weight is
    // rho' + 2 rho'' s = rho' (1 - u) / (1 + u), negative in the concave part
    // of rho (u > 1). If that makes H indefinite, the update falls back to
    // flooring it at 0 (exact_robust_hessian_ = false); the gradient
    // rho' J^T r, hence the fixed point, is the same either way.
    const double c2 = options_.cauchy_scale * options_.cauchy_scale;
    const double u = s / c2;
    f.rho1 = 1.0 / (1.0 + u);
    double curvature = (1.0 - u) / (1.0 + u);
    if (!exact_robust_hessian_) curvature = std::max(curvature, 0.0);
    f.M = f.rho1 * Matrix6d::Identity();
    if (s > 0.0) f.M += f.rho1 * (curvature - 1.0) * r * r.transpose() / s;
  }

  // Recomputes the normal-equation blocks touched by the factors in
  // `relinearized` from all factors (no add/subtract drift) and records the
  // columns whose values changed.
  void RecomputeBlocks(const std::set<int>& touched_variables) {
    for (const int v : touched_variables) {
      Matrix6d H = Matrix6d::Zero();
      Vector6d g = Vector6d::Zero();
      std::map<int, Matrix6d> off;  // H(v, w), w a neighbour
      for (const int k : variables_[v].factors) {
        const Factor& f = factors_[k];
        const bool is_a = f.a == v;
        const Matrix6d& J = is_a ? f.J_a : f.J_b;
        const Matrix6d JtM = J.transpose() * f.M;
        H.noalias() += JtM * J;
        g.noalias() -= f.rho1 * (J.transpose() * f.r);
        if (f.b >= 0) {
          const int w = is_a ? f.b : f.a;
          const Matrix6d& Jw = is_a ? f.J_b : f.J_a;
          auto [it, inserted] = off.try_emplace(w, Matrix6d::Zero());
          it->second.noalias() += JtM * Jw;
        }
      }
      H_diag_[v] = H;
      b_[v] = g;
      for (auto& [w, block] : off) {
        // Store H(min, max) once.
        if (v < w) {
          H_off_[{v, w}] = block;
        } else {
          H_off_[{w, v}] = block.transpose();
        }
        changed_columns_.insert(std::min(pos_[v], pos_[w]));
      }
      changed_columns_.insert(pos_[v]);
    }
  }

  Matrix6d HBlock(int row_var, int col_var) const {
    if (row_var < col_var) return H_off_.at({row_var, col_var});
    return H_off_.at({col_var, row_var}).transpose();
  }

  void Reorder() {
    const int n = static_cast<int>(variables_.size());
    // Approximate minimum degree on the variable graph (Eigen's AMD; on these
    // graphs a third of the fill of a breadth-first nested dissection), with
    // the newest variables constrained last, as iSAM2 does with CCOLAMD: new
    // factors mostly touch them, and their columns near the root have few
    // ancestors. AMD alone would put the middle of a long chain at the root.
    const int newest = std::min(n / 2, std::max(options_.reorder_interval, 16));
    const int older = n - newest;
    std::vector<Eigen::Triplet<double>> triplets;
    for (int v = 0; v < older; ++v) {
      triplets.emplace_back(v, v, 1.0);
      for (const int w : variables_[v].neighbours) {
        if (w < older) triplets.emplace_back(v, w, 1.0);
      }
    }
    IVec<int> order;
    order.reserve(n);
    if (older > 0) {
      Eigen::SparseMatrix<double> pattern(older, older);
      pattern.setFromTriplets(triplets.begin(), triplets.end());
      Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> permutation;
      Eigen::AMDOrdering<int> amd;
      amd(pattern, permutation);
      for (int k = 0; k < older; ++k) order.push_back(permutation.indices()[k]);
    }
    for (int v = older; v < n; ++v) order.push_back(v);
    var_at_ = order;
    pos_.assign(n, 0);
    for (int k = 0; k < n; ++k) pos_[var_at_[k]] = k;
    structure_.assign(n, {});
    L_.assign(n, {});
    L_inv_diag_.assign(n, Matrix6d::Zero());
    parent_.assign(n, -1);
    children_.assign(n, {});
    rows_.assign(n, {});
    changed_columns_.clear();
    for (int k = 0; k < n; ++k) changed_columns_.insert(k);
    appended_since_reorder_ = 0;
    ordered_ = true;
  }

  // Left-looking block Cholesky of column k given the final columns of its
  // descendants: L_kk L_kk^T = H_kk - sum_j L_kj L_kj^T and
  // L_ik = (H_ik - sum_j L_ij L_kj^T) L_kk^-T over j with L_kj != 0.
  // Returns the rows of the old structure that left it.
  IVec<int> FactorColumn(int k) {
    const int v = var_at_[k];
    IVec<int> structure;
    for (const int w : variables_[v].neighbours) {
      if (pos_[w] > k) structure.push_back(pos_[w]);
    }
    for (const int c : children_[k]) {
      for (const int i : structure_[c]) {
        if (i != k) structure.push_back(i);
      }
    }
    std::sort(structure.begin(), structure.end());
    structure.erase(std::unique(structure.begin(), structure.end()), structure.end());
    IVec<int> dropped, added;
    std::set_difference(structure_[k].begin(), structure_[k].end(), structure.begin(),
                        structure.end(), std::back_inserter(dropped));
    std::set_difference(structure.begin(), structure.end(), structure_[k].begin(),
                        structure_[k].end(), std::back_inserter(added));
    for (const int i : dropped) {
      IVec<int>& row = rows_[i];
      row.erase(std::lower_bound(row.begin(), row.end(), k));
    }
    for (const int i : added) {
      IVec<int>& row = rows_[i];
      row.insert(std::lower_bound(row.begin(), row.end(), k), k);
    }
    structure_[k] = std::move(structure);

    // Dense scratch indexed by position.
    const IVec<int>& s = structure_[k];
    for (size_t t = 0; t < s.size(); ++t) {
      slot_[s[t]] = static_cast<int>(t);
    }
    IVec<Matrix6d> acc(s.size(), Matrix6d::Zero());
    Matrix6d diag = H_diag_[v];
    for (const int w : variables_[v].neighbours) {
      if (pos_[w] > k) acc[slot_[pos_[w]]] = HBlock(w, v);
    }
    for (const int j : rows_[k]) {
      const IVec<int>& sj = structure_[j];
      const auto it = std::lower_bound(sj.begin(), sj.end(), k);
      size_t t = static_cast<size_t>(it - sj.begin());
      const Matrix6d L_kj = L_[j][t];
      diag.noalias() -= L_kj * L_kj.transpose();
      for (++t; t < sj.size(); ++t) {
        acc[slot_[sj[t]]].noalias() -= L_[j][t] * L_kj.transpose();
      }
    }
    const Eigen::LLT<Matrix6d> llt(0.5 * (diag + diag.transpose()));
    if (llt.info() != Eigen::Success) {
      throw std::runtime_error(
          "incremental solver: normal matrix not positive definite (unconstrained variable?)");
    }
    // L_kk^-1 once: the solves below and in SolveDelta / MarginalCovariance
    // become fixed-size 6x6 products (Eigen's triangular solver dispatches
    // small blocks to its general blocked kernel, the factor's hot spot).
    L_inv_diag_[k] = llt.matrixL().solve(Matrix6d::Identity());
    const Matrix6d L_inv_T = L_inv_diag_[k].transpose();
    for (Matrix6d& block : acc) {
      // X L_kk^T = A  <=>  X = A L_kk^-T.
      block = (block * L_inv_T).eval();
    }
    L_[k] = std::move(acc);
    const int parent = s.empty() ? -1 : s.front();
    if (parent != parent_[k]) {
      if (parent_[k] >= 0) {
        auto& c = children_[parent_[k]];
        c.erase(std::find(c.begin(), c.end(), k));
      }
      if (parent >= 0) children_[parent].push_back(k);
      parent_[k] = parent;
    }
    return dropped;
  }

  // Re-factors the changed columns and all their ancestors (old and new
  // elimination tree), in increasing position order.
  int Refactor() {
    std::priority_queue<int, IVec<int>, std::greater<>> queue;
    for (const int k : changed_columns_) queue.push(k);
    changed_columns_.clear();
    int last = -1, count = 0;
    while (!queue.empty()) {
      const int k = queue.top();
      queue.pop();
      if (k == last) continue;
      last = k;
      ++count;
      const int old_parent = parent_[k];
      for (const int i : FactorColumn(k)) queue.push(i);
      if (old_parent >= 0) queue.push(old_parent);
      if (parent_[k] >= 0) queue.push(parent_[k]);
    }
    return count;
  }

  void SolveDelta() {
    const int n = static_cast<int>(variables_.size());
    IVec<Vector6d> y(n);
    for (int k = 0; k < n; ++k) y[k] = b_[var_at_[k]];
    for (int k = 0; k < n; ++k) {
      y[k] = (L_inv_diag_[k] * y[k]).eval();
      const IVec<int>& s = structure_[k];
      for (size_t t = 0; t < s.size(); ++t) y[s[t]].noalias() -= L_[k][t] * y[k];
    }
    for (int k = n - 1; k >= 0; --k) {
      const IVec<int>& s = structure_[k];
      for (size_t t = 0; t < s.size(); ++t) y[k].noalias() -= L_[k][t].transpose() * y[s[t]];
      y[k] = (L_inv_diag_[k].transpose() * y[k]).eval();
      variables_[var_at_[k]].delta = y[k];
    }
  }

  // Up to `max_steps` Gauss-Newton steps, in iSAM2's order: relinearise the
  // variables the last solve moved beyond the thresholds (and the new
  // factors), re-factor the columns that reaches, solve; stop when the solve
  // moves nothing beyond them (converged).
  IncrementalPoseSolverStats Iterate(int max_steps) {
    IncrementalPoseSolverStats stats;
    const bool batch = options_.reorder_interval == 0;
    if (batch || !ordered_ || appended_since_reorder_ >= options_.reorder_interval) {
      Reorder();
      stats.reordered = true;

      if (!exact_robust_hessian_) {
        // Everything is re-factored anyway: try the exact curvature again.
        exact_robust_hessian_ = true;
        for (int k = 0; k < static_cast<int>(factors_.size()); ++k) {
          if (factors_[k].robust) pending_factors_.push_back(k);
        }
      }
    }
    std::set<int> moved = VariablesToRelinearize();
    while (true) {
      if (batch && !moved.empty()) {
        // Batch Gauss-Newton: every variable, every column, every iteration.
        for (int v = 0; v < static_cast<int>(variables_.size()); ++v) moved.insert(v);
        for (int k = 0; k < static_cast<int>(variables_.size()); ++k) changed_columns_.insert(k);
      }
      if (moved.empty() && pending_factors_.empty() && stats.iterations > 0) {
        stats.converged = true;
        break;
      }
      if (stats.iterations >= max_steps) break;
      Step(moved, &stats);
      moved = VariablesToRelinearize();
    }
    return stats;
  }

  // One Gauss-Newton step: moves the linearisation point of `moved` to its
  // estimate, relinearises their factors and the new ones, re-factors, and
  // solves for delta.
  void Step(const std::set<int>& moved, IncrementalPoseSolverStats* stats) {
    std::set<int> relinearize(pending_factors_.begin(), pending_factors_.end());
    pending_factors_.clear();
    for (const int v : moved) {
      Variable& var = variables_[v];
      std::array<double, 7> x;
      manifold_.Plus(var.theta.data(), var.delta.data(), x.data());
      var.theta = x;
      var.delta.setZero();
      for (const int k : var.factors) relinearize.insert(k);
    }
    stats->relinearized_variables += static_cast<int>(moved.size());
    std::set<int> touched;
    for (const int k : relinearize) {
      Linearize(k);
      touched.insert(factors_[k].a);
      if (factors_[k].b >= 0) touched.insert(factors_[k].b);
    }
    RecomputeBlocks(touched);
    try {
      stats->refactored_columns += Refactor();
    } catch (const std::runtime_error&) {
      if (!exact_robust_hessian_) throw;
      // Indefinite with the exact robust curvature: floor it, re-factor all.
      exact_robust_hessian_ = false;
      touched.clear();
      for (int k = 0; k < static_cast<int>(factors_.size()); ++k) {
        if (!factors_[k].robust) continue;
        Linearize(k);
        touched.insert(factors_[k].a);
        if (factors_[k].b >= 0) touched.insert(factors_[k].b);
      }
      RecomputeBlocks(touched);
      for (int k = 0; k < static_cast<int>(variables_.size()); ++k) changed_columns_.insert(k);
      stats->refactored_columns += Refactor();
      ++stats->floored_robust_hessian;
    }
    SolveDelta();
    ++stats->iterations;
  }

  // Fluid relinearisation. The residuals are linear in the translations for
  // fixed rotations (e_t = R_z^T (R_i^T (t_j - t_i) - t_z)), so the linear
  // model stays exact under translation steps except through the rotation
  // Jacobian's lever [p]x and the robust weights: a variable is relinearised
  // when its rotation step exceeds relinearize_rotation_rad or its
  // translation step relinearize_translation_m, and both variables of a
  // robust factor when its weight rho' at the predicted residual r + J delta
  // differs by more than robust_weight_tolerance (relative). With both
  // thresholds 0 every variable that moves by more than step_tolerance is.
  std::set<int> VariablesToRelinearize() const {
    std::set<int> moved;
    const double rot = std::max(options_.relinearize_rotation_rad, options_.step_tolerance);
    const double trans = std::max(options_.relinearize_translation_m, options_.step_tolerance);
    for (int v = 0; v < static_cast<int>(variables_.size()); ++v) {
      const Vector6d& d = variables_[v].delta;
      if (d.head<3>().cwiseAbs().maxCoeff() > trans || d.tail<3>().cwiseAbs().maxCoeff() > rot) {
        moved.insert(v);
      }
    }
    const double c2 = options_.cauchy_scale * options_.cauchy_scale;
    for (const int k : robust_factors_) {
      const Factor& f = factors_[k];
      Vector6d r = f.r + f.J_a * variables_[f.a].delta;
      if (f.b >= 0) r.noalias() += f.J_b * variables_[f.b].delta;
      const double rho1 = 1.0 / (1.0 + r.squaredNorm() / c2);
      if (std::abs(rho1 - f.rho1) > options_.robust_weight_tolerance * f.rho1) {
        if (MaxStep(variables_[f.a].delta) > options_.step_tolerance) moved.insert(f.a);
        if (f.b >= 0 && MaxStep(variables_[f.b].delta) > options_.step_tolerance) moved.insert(f.b);
      }
    }
    return moved;
  }

  Matrix6d MarginalCovariance(int v) const {
    // Y = L^-1 E_v is non-zero only on v's path to the root.
    std::map<int, Matrix6d> acc;
    acc[pos_[v]] = Matrix6d::Identity();
    Matrix6d sigma = Matrix6d::Zero();
    while (!acc.empty()) {
      const auto it = acc.begin();
      const int q = it->first;
      const Matrix6d Y = L_inv_diag_[q] * it->second;
      acc.erase(it);
      sigma.noalias() += Y.transpose() * Y;
      const IVec<int>& s = structure_[q];
      for (size_t t = 0; t < s.size(); ++t) {
        auto [jt, inserted] = acc.try_emplace(s[t], Matrix6d::Zero());
        jt->second.noalias() -= L_[q][t] * Y;
      }
    }
    return 0.5 * (sigma + sigma.transpose());
  }

  const IncrementalPoseSolverOptions options_;
  PoseManifold manifold_;
  IVec<Variable> variables_;
  IVec<Factor> factors_;
  IVec<int> pending_factors_;
  IVec<int> robust_factors_;
  // Normal equations H delta = b over the variables (index space).
  IVec<Matrix6d> H_diag_;
  IVec<Vector6d> b_;
  std::map<std::pair<int, int>, Matrix6d> H_off_;
  // Factor L (position space): column k holds rows structure_[k] (> k);
  // L_inv_diag_[k] is the inverse of its (lower-triangular) diagonal block.
  IVec<int> var_at_, pos_;
  IVec<IVec<int>> structure_;
  IVec<IVec<Matrix6d>> L_;
  IVec<Matrix6d> L_inv_diag_;
  IVec<int> parent_;
  IVec<IVec<int>> children_;
  IVec<IVec<int>> rows_;  // sorted: the columns j < k with L_kj != 0
  IVec<int> slot_;
  std::set<int> changed_columns_;
  int appended_since_reorder_ = 0;
  bool ordered_ = false;
  bool exact_robust_hessian_ = true;
};

IncrementalPoseSolver::IncrementalPoseSolver(const IncrementalPoseSolverOptions& options)
    : impl_(std::make_unique<Impl>(options)) {}

IncrementalPoseSolver::~IncrementalPoseSolver() = default;

int IncrementalPoseSolver::AddVariable(const double* x) {
  Impl& m = *impl_;
  const int v = static_cast<int>(m.variables_.size());
  Impl::Variable var;
  std::copy(x, x + 7, var.theta.begin());
  m.variables_.push_back(std::move(var));
  m.H_diag_.push_back(Matrix6d::Zero());
  m.b_.push_back(Vector6d::Zero());
  m.slot_.push_back(0);
  if (m.ordered_) {
    // Appended at the end of the current ordering until the next re-order.
    m.pos_.push_back(static_cast<int>(m.var_at_.size()));
    m.var_at_.push_back(v);
    m.structure_.emplace_back();
    m.L_.emplace_back();
    m.L_inv_diag_.push_back(Matrix6d::Zero());
    m.parent_.push_back(-1);
    m.children_.emplace_back();
    m.rows_.emplace_back();
    m.changed_columns_.insert(m.pos_.back());
    ++m.appended_since_reorder_;
  }
  return v;
}

void IncrementalPoseSolver::AddFactor(int a, int b, const Eigen::Isometry3d& Z,
                                      const Matrix6d& information, bool robust) {
  Impl& m = *impl_;
  const int n = static_cast<int>(m.variables_.size());
  if (a < 0 || a >= n || b >= n || a == b) {
    throw std::invalid_argument("incremental solver: factor between variables " +
                                std::to_string(a) + " and " + std::to_string(b) +
                                ", expected indices below " + std::to_string(n));
  }
  Impl::Factor f;
  f.a = a;
  f.b = b;
  f.robust = robust;
  if (b < 0) {
    f.prior = std::make_unique<PosePrior3dCost>(Z, information);
  } else {
    f.between = std::make_unique<RelativePose3dCost>(Z, information);
    for (const auto& [v, w] : {std::pair{a, b}, std::pair{b, a}}) {
      IVec<int>& list = m.variables_[v].neighbours;
      const auto it = std::lower_bound(list.begin(), list.end(), w);
      if (it == list.end() || *it != w) list.insert(it, w);
    }
  }
  const int k = static_cast<int>(m.factors_.size());
  m.variables_[a].factors.push_back(k);
  if (b >= 0) m.variables_[b].factors.push_back(k);
  if (robust) m.robust_factors_.push_back(k);
  m.factors_.push_back(std::move(f));
  m.pending_factors_.push_back(k);
}

IncrementalPoseSolverStats IncrementalPoseSolver::Update() {
  const IncrementalPoseSolverOptions& o = impl_->options_;
  return impl_->Iterate(o.steps_per_update > 0 ? std::min(o.steps_per_update, o.max_iterations)
                                               : o.max_iterations);
}

IncrementalPoseSolverStats IncrementalPoseSolver::Converge() {
  return impl_->Iterate(impl_->options_.max_iterations);
}

bool IncrementalPoseSolver::ReorderDue() const {
  const Impl& m = *impl_;
  return m.options_.reorder_interval == 0 || !m.ordered_ ||
         m.appended_since_reorder_ >= m.options_.reorder_interval;
}

void IncrementalPoseSolver::Estimate(int v, double* x) const {
  const Impl::Variable& var = impl_->variables_.at(static_cast<size_t>(v));
  impl_->manifold_.Plus(var.theta.data(), var.delta.data(), x);
}

void IncrementalPoseSolver::ScaleStep(double alpha) {
  for (Impl::Variable& var : impl_->variables_) var.delta *= alpha;
}

void IncrementalPoseSolver::ResetLinearization(const std::vector<const double*>& x_of) {
  Impl& m = *impl_;
  for (size_t v = 0; v < m.variables_.size(); ++v) {
    std::copy(x_of[v], x_of[v] + 7, m.variables_[v].theta.begin());
    m.variables_[v].delta.setZero();
  }
  m.pending_factors_.clear();
  for (size_t k = 0; k < m.factors_.size(); ++k) m.pending_factors_.push_back(static_cast<int>(k));
  m.ordered_ = false;  // re-order at the next Update()
}

IncrementalPoseSolver::Matrix6d IncrementalPoseSolver::MarginalCovariance(int v) const {
  return impl_->MarginalCovariance(v);
}

std::vector<int> IncrementalPoseSolver::Neighbourhood(const std::vector<int>& seeds,
                                                      int hops) const {
  std::set<int> reached(seeds.begin(), seeds.end());
  std::vector<int> frontier(seeds.begin(), seeds.end());
  for (int h = 0; h < hops && !frontier.empty(); ++h) {
    std::vector<int> next;
    for (const int v : frontier) {
      for (const int w : impl_->variables_[v].neighbours) {
        if (reached.insert(w).second) next.push_back(w);
      }
    }
    frontier = std::move(next);
  }
  return {reached.begin(), reached.end()};
}

int IncrementalPoseSolver::num_variables() const {
  return static_cast<int>(impl_->variables_.size());
}

}  // namespace rover::mapping
