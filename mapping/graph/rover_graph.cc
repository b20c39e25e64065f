#include "mapping/graph/rover_graph.h"

#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <array>
#include <chrono>
#include <cmath>
#include <deque>
#include <limits>
#include <optional>
#include <set>
#include <stdexcept>

#include "core/geometry/so3.h"
#include "mapping/graph/incremental_pose_solver.h"
#include "mapping/graph/pose_manifold.h"
#include "mapping/graph/relative_pose_3d_cost.h"

namespace rover::mapping {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

Matrix6d CheckedInverse(const Matrix6d& covariance, const std::string& what) {
  if (!covariance.allFinite()) throw GraphError("NaN input: covariance of " + what);
  const Eigen::LLT<Matrix6d> llt(0.5 * (covariance + covariance.transpose()));
  if (llt.info() != Eigen::Success) {
    throw GraphError("covariance of " + what + " is not positive definite");
  }
  return llt.solve(Matrix6d::Identity());
}

void CheckFinite(const Eigen::Isometry3d& T, const std::string& what) {
  if (!T.matrix().allFinite()) throw GraphError("NaN input: measurement of " + what);
}

}  // namespace

Matrix6d InformationFromCovariance(const Eigen::Isometry3d& T_a_b, const Matrix6d& covariance) {
  Matrix6d J = Matrix6d::Zero();
  J.topLeftCorner<3, 3>() = T_a_b.linear().transpose();
  J.bottomRightCorner<3, 3>() = 0.5 * Eigen::Matrix3d::Identity();
  return CheckedInverse(J * covariance * J.transpose(), "a measurement");
}

std::pair<Eigen::Isometry3d, Matrix6d> ComposeDetection(const RobotDetection& d) {
  const Eigen::Isometry3d T = d.T_body_cam * d.T_cam_marker * d.T_body_marker.inverse();
  // Perturb T_cam_marker = (p + dp, R Exp(dth)); with u = -R_B^T t_B:
  //   dt_T = R_A (dp - R_M [u]x dth),  dth_T = R_B dth.
  const Eigen::Matrix3d RA = d.T_body_cam.linear();
  const Eigen::Matrix3d RM = d.T_cam_marker.linear();
  const Eigen::Matrix3d RB = d.T_body_marker.linear();
  const Eigen::Vector3d u = -RB.transpose() * d.T_body_marker.translation();
  Matrix6d J = Matrix6d::Zero();
  J.topLeftCorner<3, 3>() = RA;
  J.topRightCorner<3, 3>() = -RA * RM * skew(u);
  J.bottomRightCorner<3, 3>() = RB;
  return {T, J * d.covariance_cam_marker * J.transpose()};
}

RoverGraphOptions RoverGraphOptions::Online() {
  RoverGraphOptions o;
  o.incremental_steps = 1;
  o.relinearize_rotation_rad = 0.002;
  o.relinearize_translation_m = 0.005;
  return o;
}

RoverGraphOptions RoverGraphOptions::Load(const ConfigNode& node) {
  RoverGraphOptions o;
  o.cauchy_scale = node.GetInRange<double>("cauchy_scale", 1e-3, 1e3, o.cauchy_scale);
  o.frame_switch_roll_pitch_sigma_rad = node.GetInRange<double>(
      "frame_switch_roll_pitch_sigma_rad", 1e-9, 0.1, o.frame_switch_roll_pitch_sigma_rad);
  o.max_iterations = node.GetInRange<int>("max_iterations", 1, 10000, o.max_iterations);
  o.num_threads = node.GetInRange<int>("num_threads", 1, 256, o.num_threads);
  o.compute_origin_covariances =
      node.Get<bool>("compute_origin_covariances", o.compute_origin_covariances);
  o.incremental = node.Get<bool>("incremental", o.incremental);
  o.incremental_solve = node.Get<bool>("incremental_solve", o.incremental_solve);
  o.relinearize_rotation_rad =
      node.GetInRange<double>("relinearize_rotation_rad", 0.0, 1.0, o.relinearize_rotation_rad);
  o.relinearize_translation_m =
      node.GetInRange<double>("relinearize_translation_m", 0.0, 100.0, o.relinearize_translation_m);
  o.reorder_interval = node.GetInRange<int>("reorder_interval", 0, 1000000, o.reorder_interval);
  o.covariance_hops = node.GetInRange<int>("covariance_hops", -1, 1000000, o.covariance_hops);
  o.incremental_steps = node.GetInRange<int>("incremental_steps", 0, 1000, o.incremental_steps);
  o.Validate();
  return o;
}

void RoverGraphOptions::Validate() const {
  const auto require = [](bool ok, const std::string& key, const std::string& expected,
                          double found) {
    if (!ok) {
      throw std::invalid_argument("RoverGraphOptions." + key + ": expected " + expected +
                                  ", found " + std::to_string(found));
    }
  };
  require(cauchy_scale > 0.0, "cauchy_scale", "> 0", cauchy_scale);
  require(frame_switch_roll_pitch_sigma_rad > 0.0, "frame_switch_roll_pitch_sigma_rad", "> 0",
          frame_switch_roll_pitch_sigma_rad);
  require(max_iterations >= 1, "max_iterations", ">= 1", max_iterations);
  require(num_threads >= 1, "num_threads", ">= 1", num_threads);
  require(relinearize_rotation_rad >= 0.0 && relinearize_rotation_rad <= 1.0,
          "relinearize_rotation_rad", "in [0, 1]", relinearize_rotation_rad);
  require(relinearize_translation_m >= 0.0 && relinearize_translation_m <= 100.0,
          "relinearize_translation_m", "in [0, 100]", relinearize_translation_m);
  require(reorder_interval >= 0, "reorder_interval", ">= 0", reorder_interval);
  require(covariance_hops >= -1, "covariance_hops", ">= -1", covariance_hops);
  require(incremental_steps >= 0, "incremental_steps", ">= 0", incremental_steps);
}

struct RoverGraph::Variable {
  std::array<double, 7> x{0, 0, 0, 0, 0, 0, 1};
  bool initialized = false;
  bool in_problem = false;
  bool in_solver = false;
};

struct RoverGraph::Factor {
  GraphKey a;
  std::optional<GraphKey> b;  // Empty for a prior.
  Eigen::Isometry3d Z = Eigen::Isometry3d::Identity();
  Matrix6d information = Matrix6d::Identity();
  Matrix6d covariance = Matrix6d::Identity();  // As given: for covariance propagation.
  bool robust = false;
  bool in_problem = false;
  bool in_solver = false;
};

class RoverGraph::Impl {
 public:
  explicit Impl(const RoverGraphOptions& options)
      : options_(options), cauchy_(options.cauchy_scale) {
    ceres::Problem::Options po;
    po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    problem_ = std::make_unique<ceres::Problem>(po);
    options_.Validate();
    if (options_.incremental && options_.incremental_solve) {
      IncrementalPoseSolverOptions io;
      io.relinearize_rotation_rad = options_.relinearize_rotation_rad;
      io.relinearize_translation_m = options_.relinearize_translation_m;
      io.reorder_interval = options_.reorder_interval;
      io.max_iterations = std::min(options_.max_iterations, 20);
      io.steps_per_update = options_.incremental_steps;
      io.cauchy_scale = options_.cauchy_scale;
      solver_ = std::make_unique<IncrementalPoseSolver>(io);
    }
  }

  void Add(Factor f, const Matrix6d& covariance, const std::string& what) {
    CheckFinite(f.Z, what);
    (void)CheckedInverse(covariance, what);
    f.information = InformationFromCovariance(f.Z, covariance);
    f.covariance = 0.5 * (covariance + covariance.transpose());
    variables_[f.a];
    if (f.b) variables_[*f.b];
    factors_.push_back(std::move(f));
  }

  void Initialise() {
    std::map<GraphKey, std::vector<size_t>> adjacency;
    std::deque<GraphKey> queue;
    bool has_prior = false;
    for (size_t k = 0; k < factors_.size(); ++k) {
      const Factor& f = factors_[k];
      if (f.in_problem) {
        // Both variables initialised already: nothing to propagate (this
        // keeps an update's cost in what it added, not in the graph's size).
        has_prior = has_prior || !f.b;
        continue;
      }
      if (!f.b) {
        has_prior = true;
        Variable& v = variables_.at(f.a);
        if (!v.initialized) {
          PoseToParameters(f.Z, v.x.data());
          v.initialized = true;
        }
        continue;
      }
      adjacency[f.a].push_back(k);
      adjacency[*f.b].push_back(k);
    }
    if (!has_prior) {
      throw GraphError(
          "gauge problem: the graph has no prior; add a prior on each robot's first origin");
    }
    // Only the factors outside the problem can reach a variable that is not
    // initialised yet: start from their initialised ends.
    for (const auto& [key, factors] : adjacency) {
      if (variables_.at(key).initialized) queue.push_back(key);
    }
    while (!queue.empty()) {
      const GraphKey key = queue.front();
      queue.pop_front();
      const Eigen::Isometry3d T = PoseFromParameters(variables_.at(key).x.data());
      for (const size_t k : adjacency[key]) {
        const Factor& f = factors_[k];
        const bool forward = f.a == key;
        Variable& other = variables_.at(forward ? *f.b : f.a);
        if (other.initialized) continue;
        PoseToParameters(
            forward ? Eigen::Isometry3d(T * f.Z) : Eigen::Isometry3d(T * f.Z.inverse()),
            other.x.data());
        other.initialized = true;
        queue.push_back(forward ? *f.b : f.a);
      }
    }
    // Every variable has a factor; one that is not initialised has one
    // outside the problem that is not a prior, so it is in `adjacency`.
    unanchored_.clear();
    for (const auto& [key, factors] : adjacency) {
      if (!variables_.at(key).initialized) unanchored_.push_back(key);
    }
  }

  // A factor can enter the problem once both its variables are anchored.
  bool Ready(const Factor& f) const {
    return variables_.at(f.a).initialized && (!f.b || variables_.at(*f.b).initialized);
  }

  // True when the factors not yet in the problem only hang new variables
  // off the graph as a forest (each new variable reached by exactly one new
  // factor, priors counting as links to the anchored graph): composing them
  // then gives every new factor a zero residual, so the optimum of the
  // variables already there does not move and no solve is needed.
  bool PendingFactorsExtendTheGraph() const {
    std::map<GraphKey, GraphKey> parent;               // union-find over new variables
    const GraphKey anchored = GraphKey::Landmark(-1);  // stands for the existing graph
    const auto root = [&](GraphKey k) {
      if (const auto it = variables_.find(k); it != variables_.end() && it->second.in_problem) {
        return anchored;
      }
      while (parent.count(k) != 0 && parent.at(k) != k) k = parent.at(k);
      return k;
    };
    for (const Factor& f : factors_) {
      if (f.in_problem || !Ready(f)) continue;
      const GraphKey ra = root(f.a);
      const GraphKey rb = f.b ? root(*f.b) : anchored;
      if (ra == rb) return false;  // closes a loop (or joins two old variables)
      if (ra == anchored) {
        parent[rb] = ra;
      } else {
        parent[ra] = rb;
      }
      if (parent.count(ra) == 0) parent[ra] = ra;
      if (parent.count(rb) == 0) parent[rb] = rb;
    }
    return true;
  }

  // Marginal covariance of each new origin from its parent's, through the
  // composition T_b = T_a Z: with the tangent [dt (world); dphi (right)] and
  // Z's covariance over [dp (frame a); dtheta (right)],
  //   Sigma_b = J_a Sigma_a J_a^T + J_z Sigma_z J_z^T,
  //   J_a = [[I, -R_a [t_z]x], [0, R_z^T]],  J_z = [[R_a, 0], [0, I]].
  // For a leaf this is the exact (linearised) marginal. Priors give their own
  // covariance. Returns false if some new origin cannot be reached that way.
  bool PropagateCovariancesToNewOrigins() {
    bool progress = true;
    std::vector<const Factor*> pending;
    for (const Factor& f : factors_) {
      if (!f.in_problem && Ready(f)) pending.push_back(&f);
    }
    while (progress) {
      progress = false;
      for (const Factor* f : pending) {
        if (!f->b) {
          if (f->a.type == GraphKey::Type::kOrigin && origin_covariance_.count(f->a) == 0) {
            SetOriginCovariance(f->a, f->covariance);
            progress = true;
          }
          continue;
        }
        const GraphKey& b = *f->b;
        if (b.type != GraphKey::Type::kOrigin || origin_covariance_.count(b) != 0) continue;
        const auto a_cov = origin_covariance_.find(f->a);
        if (a_cov == origin_covariance_.end()) continue;
        const Eigen::Matrix3d R_a = PoseFromParameters(variables_.at(f->a).x.data()).linear();
        Matrix6d J_a = Matrix6d::Identity();
        J_a.topRightCorner<3, 3>() = -R_a * skew(f->Z.translation());
        J_a.bottomRightCorner<3, 3>() = f->Z.linear().transpose();
        Matrix6d J_z = Matrix6d::Identity();
        J_z.topLeftCorner<3, 3>() = R_a;
        SetOriginCovariance(b, J_a * CurrentOriginCovariance(f->a) * J_a.transpose() +
                                   J_z * f->covariance * J_z.transpose());
        progress = true;
      }
    }
    for (const Factor* f : pending) {
      for (const GraphKey& k : {f->a, f->b.value_or(f->a)}) {
        if (k.type == GraphKey::Type::kOrigin && origin_covariance_.count(k) == 0) return false;
      }
    }
    return true;
  }

  void AddPendingToProblem() {
    for (auto& [key, v] : variables_) {
      if (v.in_problem || !v.initialized) continue;
      problem_->AddParameterBlock(v.x.data(), 7, &manifold_);
      v.in_problem = true;
    }
    for (Factor& f : factors_) {
      if (f.in_problem || !Ready(f)) continue;
      ceres::LossFunction* loss = f.robust ? &cauchy_ : nullptr;
      double* a = variables_.at(f.a).x.data();
      if (f.b) {
        problem_->AddResidualBlock(new RelativePose3dCost(f.Z, f.information), loss, a,
                                   variables_.at(*f.b).x.data());
      } else {
        problem_->AddResidualBlock(new PosePrior3dCost(f.Z, f.information), loss, a);
      }
      f.in_problem = true;
    }
  }

  RoverGraphSummary Optimize() {
    RoverGraphSummary out;
    Initialise();
    out.unanchored = unanchored_;
    const Clock::time_point start = Clock::now();
    if (options_.incremental && solved_once_ && PendingFactorsExtendTheGraph()) {
      // Exact without a solve (see above); only the new covariances are due.
      const bool covariances_known =
          !options_.compute_origin_covariances || PropagateCovariancesToNewOrigins();
      AddPendingToProblem();
      AddPendingToSolver();
      if (solver_ && options_.reorder_interval > 0 && solver_->ReorderDue()) ReorderSolver(&out);
      out.variables = static_cast<int>(variables_.size());
      out.factors = static_cast<int>(factors_.size());
      out.converged = true;
      out.final_cost = out.initial_cost = last_cost_;
      if (covariances_known) {
        out.solve_time_s = Seconds(start);
        return out;
      }
    }
    if (solver_ && solved_once_) return SolveIncrementally(out);
    return Solve(out);
  }

  // The incremental solver's periodic re-ordering (a full re-factorisation)
  // on an update that only extends the graph, which otherwise costs nothing,
  // instead of on the next loop closure, whose own work it would add to.
  void ReorderSolver(RoverGraphSummary* out) {
    const CostedEstimate before = CurrentEstimate();
    try {
      const IncrementalPoseSolverStats stats = solver_->Update();
      out->refactored_columns = stats.refactored_columns;
      out->reordered = stats.reordered;
      bool shortened = false;
      refine_steps_ = 0;
      if (CostIfLower(before, &shortened)) {
        refine_due_ = !stats.converged || shortened;
        return;
      }
    } catch (const std::runtime_error&) {
    }
    // Singular, or a step that raised the cost: start the solver over from
    // the estimate as it was; the next loop closure decides.
    refine_due_ = false;
    ResetSolver();
  }

  void CopySolverEstimates() {
    for (size_t i = 0; i < solver_variables_.size(); ++i) {
      solver_->Estimate(static_cast<int>(i), solver_variables_[i]->x.data());
    }
  }

  void ResetSolver() {
    std::vector<const double*> x_of;
    for (const Variable* v : solver_variables_) x_of.push_back(v->x.data());
    solver_->ResetLinearization(x_of);
  }

  // Mirrors the variables and factors of the Ceres problem into the
  // incremental solver; returns the solver indices of the new factors'
  // variables (where the marginals change most).
  std::vector<int> AddPendingToSolver() {
    std::vector<int> touched;
    if (!solver_) return touched;
    for (auto& [key, v] : variables_) {
      if (!v.in_problem || v.in_solver) continue;
      solver_index_[key] = solver_->AddVariable(v.x.data());
      solver_keys_.push_back(key);
      solver_variables_.push_back(&v);
      v.in_solver = true;
    }
    for (Factor& f : factors_) {
      if (!f.in_problem || f.in_solver) continue;
      const int a = solver_index_.at(f.a);
      const int b = f.b ? solver_index_.at(*f.b) : -1;
      solver_->AddFactor(a, b, f.Z, f.information, f.robust);
      f.in_solver = true;
      touched.push_back(a);
      if (b >= 0) touched.push_back(b);
    }
    return touched;
  }

  // Loop-closing update without a full solve: the incremental Gauss-Newton
  // touches the changed part of the factor; the origin marginals near the new
  // factors are recomputed, the others kept (see RoverGraphOptions).
  RoverGraphSummary SolveIncrementally(RoverGraphSummary out) {
    AddPendingToProblem();
    const std::vector<int> seeds = AddPendingToSolver();
    const Clock::time_point start = Clock::now();
    const CostedEstimate before = CurrentEstimate();
    IncrementalPoseSolverStats stats;
    try {
      stats = solver_->Update();
    } catch (const std::runtime_error&) {
      return Solve(out);  // singular system: let Ceres (with its damping) decide
    }
    // Converging updates that do not converge fall back to Ceres; with a
    // fixed number of steps the next updates carry on from here.
    if (!stats.converged && options_.incremental_steps == 0) return Solve(out);
    bool shortened = false;
    const std::optional<double> cost = CostIfLower(before, &shortened);
    if (!cost) return Solve(out);
    refine_due_ = !stats.converged || shortened;
    refine_steps_ = 0;
    AcceptIncrementalStep(stats, *cost, start, &out);
    out.reordered = stats.reordered;
    out.variables = static_cast<int>(variables_.size());
    out.factors = static_cast<int>(factors_.size());
    if (options_.compute_origin_covariances) {
      const Clock::time_point cov_start = Clock::now();
      std::vector<int> targets;
      if (options_.covariance_hops < 0) {
        for (size_t i = 0; i < solver_keys_.size(); ++i) targets.push_back(static_cast<int>(i));
      } else {
        targets = solver_->Neighbourhood(seeds, options_.covariance_hops);
        for (size_t i = 0; i < solver_keys_.size(); ++i) {
          if (origin_covariance_.count(solver_keys_[i]) == 0)
            targets.push_back(static_cast<int>(i));
        }
      }
      for (const int i : targets) {
        const GraphKey& key = solver_keys_[static_cast<size_t>(i)];
        if (key.type != GraphKey::Type::kOrigin) continue;
        SetOriginCovariance(key, solver_->MarginalCovariance(i));
        ++out.covariances_updated;
      }
      out.covariance_time_s = Seconds(cov_start);
    }
    return out;
  }

  bool NeedsRefinement() const { return solver_ != nullptr && refine_due_; }

  // One incremental step on the factors already in the solver (nothing new
  // is added: factors received since the last Optimize() wait for it).
  RoverGraphSummary Refine() {
    RoverGraphSummary out;
    out.unanchored = unanchored_;
    out.variables = static_cast<int>(variables_.size());
    out.factors = static_cast<int>(factors_.size());
    if (!NeedsRefinement()) {
      out.converged = true;
      out.final_cost = out.initial_cost = last_cost_;
      return out;
    }
    const Clock::time_point start = Clock::now();
    const CostedEstimate before = CurrentEstimate();
    IncrementalPoseSolverStats stats;
    try {
      stats = solver_->Update();
    } catch (const std::runtime_error&) {
      refine_due_ = false;
      return Solve(out);
    }
    ++refine_steps_;
    bool shortened = false;
    const std::optional<double> cost = CostIfLower(before, &shortened);
    refine_due_ = !stats.converged || shortened;
    if (!cost || (refine_due_ && refine_steps_ >= MaxRefineSteps())) {
      // As a converging update does: what undamped Gauss-Newton does not
      // settle (a robust factor's weight swinging after a large correction
      // raises the cost, or the steps never end), Ceres's trust region does,
      // and the swinging estimate is never published.
      return Solve(out);
    }
    AcceptIncrementalStep(stats, *cost, start, &out);
    return out;
  }

  // The variables' values and the true cost 1/2 sum rho(|r|^2) there.
  struct CostedEstimate {
    std::vector<std::array<double, 7>> x;  // by solver index
    double cost = 0.0;
  };

  CostedEstimate CurrentEstimate() const {
    CostedEstimate e;
    e.x.reserve(solver_variables_.size());
    for (const Variable* v : solver_variables_) e.x.push_back(v->x);
    e.cost = ProblemCost();
    return e;
  }

  double ProblemCost() const {
    double cost = 0.0;
    if (!problem_->Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr, nullptr)) {
      return std::numeric_limits<double>::infinity();
    }
    return cost;
  }

  // Takes the incremental solver's estimate if it lowers the true cost, and
  // returns that cost; otherwise halves the step (a backtracking line search)
  // up to kMaxStepHalvings times, and failing that puts `before` back and
  // returns nothing (the caller hands the graph to Ceres). An undamped
  // Gauss-Newton step with the exact robust curvature is only as good as its
  // quadratic model: a loop closure's full step often overshoots, and a new
  // sighting contradicting a landmark's earlier ones left the curvature
  // along its residual nearly zero, so that one step threw a variable 4e8 m
  // away, into the flat tail of the Cauchy loss where no solver brings it
  // back. *shortened: the step taken is a fraction of the full one.
  std::optional<double> CostIfLower(const CostedEstimate& before, bool* shortened) {
    for (int halvings = 0; halvings <= kMaxStepHalvings; ++halvings) {
      CopySolverEstimates();
      const double cost = ProblemCost();
      if (std::isfinite(cost) && cost <= before.cost * (1.0 + kCostTolerance)) {
        *shortened = halvings > 0;
        return cost;
      }
      solver_->ScaleStep(0.5);
    }
    for (size_t i = 0; i < solver_variables_.size(); ++i) solver_variables_[i]->x = before.x[i];
    return std::nullopt;
  }

  // A step that leaves the cost within this fraction of where it was stands:
  // at convergence the cost changes by rounding alone.
  static constexpr double kCostTolerance = 1e-9;
  // Down to 1/64 of the Gauss-Newton step before Ceres takes over.
  static constexpr int kMaxStepHalvings = 6;

  // An incremental step that stands: its estimates become the graph's, and
  // the summary says what it did.
  void AcceptIncrementalStep(const IncrementalPoseSolverStats& stats, double cost,
                             Clock::time_point start, RoverGraphSummary* out) {
    out->solve_time_s = Seconds(start);
    out->iterations = stats.iterations;
    out->initial_cost = last_cost_;
    out->final_cost = last_cost_ = cost;
    out->converged = stats.converged && !refine_due_;
    out->solved = true;
    out->incremental_solve = true;
    out->relinearized = stats.relinearized_variables;
    out->refactored_columns = stats.refactored_columns;
  }

  RoverGraphSummary Solve(RoverGraphSummary out) {
    refine_due_ = false;
    AddPendingToProblem();
    ceres::Solver::Options so;
    so.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    so.sparse_linear_algebra_library_type =
        ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE) ? ceres::SUITE_SPARSE
                                                                              : ceres::EIGEN_SPARSE;
    so.max_num_iterations = options_.max_iterations;
    so.num_threads = options_.num_threads;
    so.function_tolerance = 1e-12;
    so.gradient_tolerance = 1e-12;
    so.parameter_tolerance = 1e-12;
    so.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    const Clock::time_point start = Clock::now();
    ceres::Solve(so, problem_.get(), &summary);
    out.solve_time_s = Seconds(start);
    out.iterations = static_cast<int>(summary.iterations.size()) - 1;
    out.initial_cost = summary.initial_cost;
    out.final_cost = summary.final_cost;
    out.converged = summary.termination_type == ceres::CONVERGENCE;
    out.solved = true;
    solved_once_ = true;
    last_cost_ = summary.final_cost;
    out.variables = static_cast<int>(variables_.size());
    out.factors = static_cast<int>(factors_.size());
    if (options_.compute_origin_covariances) {
      const Clock::time_point cov_start = Clock::now();
      // A failure here must not leave the incremental solver behind the
      // solve below: that state diverged in a mission (hundreds of metres).
      try {
        ComputeOriginCovariances();
      } catch (const GraphError& e) {
        out.covariance_error = e.what();
      }
      out.covariance_time_s = Seconds(cov_start);
    } else {
      origin_covariance_.clear();
    }
    if (solver_) {
      // The incremental solver continues from this optimum.
      AddPendingToSolver();
      ResetSolver();
    }
    return out;
  }

  // Stores a marginal with the origin's current rotation: the translation
  // block is over world axes, so a marginal kept while later solves rotate
  // the origin is re-expressed with the rotation change (OriginCovariance).
  void SetOriginCovariance(const GraphKey& key, const Matrix6d& covariance) {
    origin_covariance_[key] = covariance;
    covariance_rotation_[key] = PoseFromParameters(variables_.at(key).x.data()).linear();
  }

  Matrix6d CurrentOriginCovariance(const GraphKey& key) const {
    const auto it = origin_covariance_.find(key);
    if (it == origin_covariance_.end()) throw GraphError("no covariance for " + key.ToString());
    Matrix6d G = Matrix6d::Identity();
    G.topLeftCorner<3, 3>() = PoseFromParameters(variables_.at(key).x.data()).linear() *
                              covariance_rotation_.at(key).transpose();
    return G * it->second * G.transpose();
  }

  void ComputeOriginCovariances() {
    ceres::Covariance::Options co;
    co.num_threads = options_.num_threads;
    co.algorithm_type = ceres::SPARSE_QR;
    ceres::Covariance covariance(co);
    std::vector<std::pair<const double*, const double*>> blocks;
    for (const auto& [key, v] : variables_) {
      if (key.type == GraphKey::Type::kOrigin && v.in_problem) {
        blocks.emplace_back(v.x.data(), v.x.data());
      }
    }
    if (!covariance.Compute(blocks, problem_.get())) {
      throw GraphError(
          "origin covariances: the problem is rank deficient (gauge problem?); the last ones "
          "are kept");
    }
    for (const auto& [key, v] : variables_) {
      if (key.type != GraphKey::Type::kOrigin || !v.in_problem) continue;
      Eigen::Matrix<double, 6, 6, Eigen::RowMajor> C;
      covariance.GetCovarianceBlockInTangentSpace(v.x.data(), v.x.data(), C.data());
      SetOriginCovariance(key, C);
    }
  }

  const RoverGraphOptions options_;
  std::unique_ptr<IncrementalPoseSolver> solver_;
  std::map<GraphKey, int> solver_index_;
  std::vector<GraphKey> solver_keys_;        // by solver index
  std::vector<Variable*> solver_variables_;  // the same (std::map nodes are stable)
  PoseManifold manifold_;
  ceres::CauchyLoss cauchy_;
  std::map<GraphKey, Variable> variables_;
  std::vector<Factor> factors_;
  std::map<GraphKey, Matrix6d> origin_covariance_;
  std::map<GraphKey, Eigen::Matrix3d> covariance_rotation_;  // R_world_origin when computed
  std::vector<GraphKey> unanchored_;
  bool solved_once_ = false;
  double last_cost_ = 0.0;
  int MaxRefineSteps() const { return std::min(options_.max_iterations, 20); }

  // A one-step update (options_.incremental_steps > 0) left the estimate
  // short of convergence: Refine() carries on, then Ceres after
  // MaxRefineSteps() steps.
  bool refine_due_ = false;
  int refine_steps_ = 0;
  struct FilterPose {
    int64_t submap = 0;
    int64_t pose = 0;
    Eigen::Isometry3d T_local_body = Eigen::Isometry3d::Identity();
  };
  std::map<int, FilterPose> current_filter_pose_;
  std::map<int, FilterPose> latest_v_;
  std::unique_ptr<ceres::Problem> problem_;  // Declared last: destroyed first.
};

RoverGraph::RoverGraph(const RoverGraphOptions& options) : impl_(std::make_unique<Impl>(options)) {}

RoverGraph::~RoverGraph() = default;

void RoverGraph::AddPrior(const GraphKey& key, const Eigen::Isometry3d& T_world_key,
                          const Matrix6d& covariance) {
  Factor f;
  f.a = key;
  f.Z = T_world_key;
  impl_->Add(std::move(f), covariance, "prior on " + key.ToString());
}

void RoverGraph::AddBetween(const GraphKey& a, const GraphKey& b, const Eigen::Isometry3d& T_a_b,
                            const Matrix6d& covariance, bool robust) {
  if (a == b) throw GraphError("factor between " + a.ToString() + " and itself");
  Factor f;
  f.a = a;
  f.b = b;
  f.Z = T_a_b;
  f.robust = robust;
  impl_->Add(std::move(f), covariance, "factor " + a.ToString() + " -> " + b.ToString());
}

void RoverGraph::AddOriginPrior(int robot, const Eigen::Isometry3d& T_world_origin,
                                const Matrix6d& covariance) {
  AddPrior(GraphKey::Origin(robot, 0), T_world_origin, covariance);
}

void RoverGraph::AddFrameSwitch(int robot, int64_t submap, const Eigen::Isometry3d& T_old_new,
                                const Matrix4d& covariance) {
  // Expand [dp; dyaw] to [dp; dtheta]: for a rotation about z, a right
  // perturbation about z is an additive yaw change, so dtheta_z = dyaw; roll
  // and pitch get the stiff prior.
  Matrix6d C = Matrix6d::Zero();
  const int map[4] = {0, 1, 2, 5};
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) C(map[r], map[c]) = covariance(r, c);
  }
  const double s2 = impl_->options_.frame_switch_roll_pitch_sigma_rad *
                    impl_->options_.frame_switch_roll_pitch_sigma_rad;
  C(3, 3) = s2;
  C(4, 4) = s2;
  AddBetween(GraphKey::Origin(robot, submap), GraphKey::Origin(robot, submap + 1), T_old_new, C,
             false);
}

void RoverGraph::AddFilterPose(int robot, int64_t submap, int64_t pose,
                               const Eigen::Isometry3d& T_local_body, const Matrix6d& covariance) {
  AddBetween(GraphKey::Origin(robot, submap), GraphKey::Pose(robot, pose), T_local_body, covariance,
             false);
  auto it = impl_->latest_v_.find(robot);
  if (it == impl_->latest_v_.end() || pose >= it->second.pose) {
    impl_->latest_v_[robot] = {submap, pose, T_local_body};
  }
}

void RoverGraph::AddSubmapMatch(int robot_a, int64_t submap_a, int robot_b, int64_t submap_b,
                                const Eigen::Isometry3d& T_a_b, const Matrix6d& covariance) {
  AddBetween(GraphKey::Origin(robot_a, submap_a), GraphKey::Origin(robot_b, submap_b), T_a_b,
             covariance, true);
}

void RoverGraph::AddRobotDetection(int observer, int64_t observer_pose, int target,
                                   int64_t target_pose, const RobotDetection& detection) {
  const auto [T, C] = ComposeDetection(detection);
  AddBetween(GraphKey::Pose(observer, observer_pose), GraphKey::Pose(target, target_pose), T, C,
             true);
}

void RoverGraph::AddLandmarkObservation(int robot, int64_t pose, int64_t landmark,
                                        const Eigen::Isometry3d& T_body_landmark,
                                        const Matrix6d& covariance) {
  AddBetween(GraphKey::Pose(robot, pose), GraphKey::Landmark(landmark), T_body_landmark, covariance,
             true);
}

void RoverGraph::SetCurrentFilterPose(int robot, int64_t submap,
                                      const Eigen::Isometry3d& T_local_body) {
  CheckFinite(T_local_body, "current filter pose");
  impl_->current_filter_pose_[robot] = {submap, 0, T_local_body};
}

RoverGraphSummary RoverGraph::Optimize() { return impl_->Optimize(); }

bool RoverGraph::NeedsRefinement() const { return impl_->NeedsRefinement(); }

RoverGraphSummary RoverGraph::Refine() { return impl_->Refine(); }

Eigen::Isometry3d RoverGraph::Estimate(const GraphKey& key) const {
  const auto it = impl_->variables_.find(key);
  if (it == impl_->variables_.end() || !it->second.initialized) {
    throw GraphError("no estimate for " + key.ToString());
  }
  return PoseFromParameters(it->second.x.data());
}

Matrix6d RoverGraph::OriginCovariance(int robot, int64_t submap) const {
  const GraphKey key = GraphKey::Origin(robot, submap);
  return impl_->CurrentOriginCovariance(key);
}

Eigen::Isometry3d RoverGraph::GlobalPose(int robot) const {
  auto it = impl_->current_filter_pose_.find(robot);
  if (it == impl_->current_filter_pose_.end()) {
    it = impl_->latest_v_.find(robot);
    if (it == impl_->latest_v_.end()) {
      throw GraphError("no filter pose for robot " + std::to_string(robot));
    }
  }
  return Origin(robot, it->second.submap) * it->second.T_local_body;
}

std::vector<GraphKey> RoverGraph::Keys() const {
  std::vector<GraphKey> keys;
  for (const auto& [key, v] : impl_->variables_) keys.push_back(key);
  return keys;
}

}  // namespace rover::mapping
