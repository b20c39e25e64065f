#include "mapping/graph/pose_graph_solver.h"

#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "core/stats/chi_square.h"
#include "mapping/graph/chordal_initialisation.h"
#include "mapping/graph/chordal_pose_2d_cost.h"
#include "mapping/graph/chordal_pose_3d_cost.h"
#include "mapping/graph/graph_connectivity.h"
#include "mapping/graph/pose_manifold.h"
#include "mapping/graph/relative_pose_2d_cost.h"
#include "mapping/graph/relative_pose_3d_cost.h"
#include "mapping/graph/se_sync_newton_solver.h"
#include "mapping/graph/se_sync_objective.h"
#include "mapping/graph/se_sync_staircase.h"

namespace rover::mapping {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

// rho(s) = w s with a weight that GNC changes between solves.
class WeightLoss final : public ceres::LossFunction {
 public:
  void Evaluate(double s, double rho[3]) const override {
    rho[0] = weight * s;
    rho[1] = weight;
    rho[2] = 0.0;
  }
  double weight = 1.0;
};

class ProgressCallback final : public ceres::IterationCallback {
 public:
  ProgressCallback(const std::function<void(int, double, double)>& f, Clock::time_point start)
      : f_(f), start_(start) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    f_(s.iteration, s.cost, Seconds(start_));
    return ceres::SOLVER_CONTINUE;
  }

 private:
  const std::function<void(int, double, double)>& f_;
  Clock::time_point start_;
};

// The Ceres problem of one g2o graph: one parameter block per vertex.
class Problem {
 public:
  // Only edges with (*active)[k] true (all if null) get a residual block, so
  // rejected edges cost nothing (not even fill-in).
  // `loop_losses` (if given, one per edge) replace the options' loss on loop
  // closures.
  Problem(PoseGraph& graph, const PoseGraphSolverOptions& options,
          const std::vector<bool>* active = nullptr, std::vector<WeightLoss>* loop_losses = nullptr)
      : graph_(graph), options_(options), planar_(graph.dimension == 2) {
    ceres::Problem::Options po;
    po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    po.enable_fast_removal = false;
    problem_ = std::make_unique<ceres::Problem>(po);
    const size_t n = graph.vertices.size();
    stride_ = planar_ ? 3 : 7;
    params_.resize(n * stride_);
    ToParameters();
    for (size_t k = 0; k < n; ++k) {
      if (planar_) {
        problem_->AddParameterBlock(Block(k), 3);
      } else {
        problem_->AddParameterBlock(Block(k), 7, &manifold_);
      }
    }
    problem_->SetParameterBlockConstant(Block(0));
    const auto index = VertexIndex(graph);
    cauchy_ = std::make_unique<ceres::CauchyLoss>(options.cauchy_scale);
    residual_ids_.assign(graph.edges.size(), nullptr);
    for (size_t k = 0; k < graph.edges.size(); ++k) {
      if (active != nullptr && !(*active)[k]) continue;
      const PoseEdge& e = graph.edges[k];
      double* bi = Block(static_cast<size_t>(index.at(e.from)));
      double* bj = Block(static_cast<size_t>(index.at(e.to)));
      ceres::LossFunction* loss = nullptr;
      if (IsLoopClosure(e)) {
        if (options.outliers == OutlierHandling::kCauchy) loss = cauchy_.get();
        if (loop_losses != nullptr) loss = &(*loop_losses)[k];
      }
      residual_ids_[k] = problem_->AddResidualBlock(MakeCost(e), loss, bi, bj);
    }
  }

  ceres::CostFunction* MakeCost(const PoseEdge& e) const {
    if (options_.objective == Objective::kSeSync) {
      const IsotropicWeights w = SeSyncWeights(e, graph_.dimension);
      if (planar_) return new ChordalPose2dCost(PlanarPose(e.measurement), w.kappa, w.tau);
      return new ChordalPose3dCost(e.measurement, w.kappa, w.tau);
    }
    if (planar_) {
      return new RelativePose2dCost(PlanarPose(e.measurement), PlanarInformation(e.information));
    }
    return new RelativePose3dCost(e.measurement, e.information);
  }

  double* Block(size_t k) { return params_.data() + k * stride_; }

  void ToParameters() {
    for (size_t k = 0; k < graph_.vertices.size(); ++k) {
      const Eigen::Isometry3d& T = graph_.vertices[k].pose;
      if (planar_) {
        const Eigen::Vector3d p = PlanarPose(T);
        std::copy(p.data(), p.data() + 3, Block(k));
      } else {
        PoseToParameters(T, Block(k));
      }
    }
  }

  void FromParameters() {
    for (size_t k = 0; k < graph_.vertices.size(); ++k) {
      const double* b = Block(k);
      graph_.vertices[k].pose =
          planar_ ? PoseFromPlanar(b[0], b[1], WrapAngle(b[2])) : PoseFromParameters(b);
    }
  }

  // Squared residual norm of every edge (without loss).
  std::vector<double> SquaredResiduals() {
    std::vector<double> out(residual_ids_.size());
    const int size = planar_ ? (options_.objective == Objective::kSeSync ? 4 : 3)
                             : (options_.objective == Objective::kSeSync ? 12 : 6);
    std::vector<double> r(static_cast<size_t>(size));
    for (size_t k = 0; k < residual_ids_.size(); ++k) {
      if (residual_ids_[k] == nullptr) continue;
      double cost = 0.0;
      problem_->EvaluateResidualBlock(residual_ids_[k], false, &cost, r.data(), nullptr);
      double s = 0.0;
      for (const double v : r) s += v * v;
      out[k] = s;
    }
    return out;
  }

  ceres::Solver::Summary Solve(int max_iterations, Clock::time_point start) {
    ceres::Solver::Options so;
    so.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    so.sparse_linear_algebra_library_type =
        !options_.eigen_sparse &&
                ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE)
            ? ceres::SUITE_SPARSE
            : ceres::EIGEN_SPARSE;
    so.jacobi_scaling = options_.jacobi_scaling;
    so.trust_region_strategy_type = options_.dogleg ? ceres::DOGLEG : ceres::LEVENBERG_MARQUARDT;
    so.initial_trust_region_radius = options_.initial_trust_region_radius;

    so.max_num_iterations = max_iterations;
    so.num_threads = options_.num_threads;
    so.function_tolerance = options_.function_tolerance;
    so.gradient_tolerance = options_.gradient_tolerance;
    so.parameter_tolerance = options_.parameter_tolerance;
    so.minimizer_progress_to_stdout = false;
    so.logging_type = ceres::SILENT;
    ProgressCallback callback(options_.progress, start);
    if (options_.progress) so.callbacks.push_back(&callback);
    ceres::Solver::Summary summary;
    ceres::Solve(so, problem_.get(), &summary);
    return summary;
  }

 private:
  PoseGraph& graph_;
  const PoseGraphSolverOptions& options_;
  bool planar_;
  size_t stride_ = 7;
  std::vector<double> params_;
  PoseManifold manifold_;
  std::unique_ptr<ceres::CauchyLoss> cauchy_;
  std::vector<ceres::ResidualBlockId> residual_ids_;
  std::unique_ptr<ceres::Problem> problem_;  // Destroyed first: it points at the above.
};

}  // namespace

bool IsLoopClosure(const PoseEdge& edge) { return std::llabs(edge.to - edge.from) != 1; }

std::string InformationUse::Describe() const {
  if (off_diagonal_ignored == 0) return "";
  std::ostringstream os;
  os << off_diagonal_ignored << (off_diagonal_ignored == 1 ? " edge" : " edges")
     << ": off-diagonal blocks ignored";
  if (indefinite > 0) {
    os << "; " << indefinite << " of them"
       << ": info matrix indefinite as a whole";
    if (first_indefinite_line > 0) os << " (first on line " << first_indefinite_line << ")";
  }
  return os.str();
}

namespace {

// The information matrix an edge's chi2 residual weights: 6x6 in 3D, the
// (x, y, theta) 3x3 in 2D.
Eigen::MatrixXd WeightedInformation(const PoseEdge& edge, int dimension) {
  if (dimension == 2) return PlanarInformation(edge.information);
  return edge.information;
}

bool HasOffDiagonalBlock(const Eigen::MatrixXd& information) {
  const int t = information.rows() == 6 ? 3 : 2;
  return !information.topRightCorner(t, information.cols() - t).isZero(0.0);
}

}  // namespace

InformationUse CheckInformation(const PoseGraph& graph, Objective objective) {
  InformationUse use;
  int first_bad = -1;
  double first_bad_eigenvalue = 0.0;
  for (size_t k = 0; k < graph.edges.size(); ++k) {
    const Eigen::MatrixXd I = WeightedInformation(graph.edges[k], graph.dimension);
    if (!HasOffDiagonalBlock(I)) continue;  // Diagonal blocks are positive definite.
    ++use.off_diagonal_ignored;
    if (Eigen::LLT<Eigen::MatrixXd>(I).info() == Eigen::Success) continue;
    ++use.indefinite;
    if (first_bad < 0) {
      first_bad = static_cast<int>(k);
      first_bad_eigenvalue = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(I).eigenvalues()(0);
      use.first_indefinite_line = graph.edges[k].line;
    }
  }
  if (objective == Objective::kChi2 && first_bad >= 0) {
    const PoseEdge& e = graph.edges[static_cast<size_t>(first_bad)];
    std::ostringstream os;
    os << graph.source << ":"
       << (e.line > 0 ? std::to_string(e.line) : "edge " + std::to_string(first_bad)) << ": edge "
       << e.from << " -> " << e.to
       << ": expected a positive-definite information matrix for the chi2 objective, found "
          "smallest eigenvalue "
       << first_bad_eigenvalue;
    if (use.indefinite > 1) os << " (and " << use.indefinite - 1 << " more such edges)";
    os << "; the sesync objective uses only its rotation and translation blocks";
    throw GraphError(os.str());
  }
  if (objective == Objective::kChi2) use.off_diagonal_ignored = 0;  // chi2 uses them.
  return use;
}

PoseGraphSolverOptions PoseGraphSolverOptions::Load(const ConfigNode& node) {
  PoseGraphSolverOptions o;
  o.objective = node.GetEnum<Objective>(
      "objective", {{"chi2", Objective::kChi2}, {"sesync", Objective::kSeSync}}, o.objective);
  o.initialisation = node.GetEnum<Initialisation>("initialisation",
                                                  {{"chordal", Initialisation::kChordal},
                                                   {"odometry", Initialisation::kOdometry},
                                                   {"file", Initialisation::kFile}},
                                                  o.initialisation);
  o.outliers = node.GetEnum<OutlierHandling>("outliers",
                                             {{"none", OutlierHandling::kNone},
                                              {"cauchy", OutlierHandling::kCauchy},
                                              {"gnc", OutlierHandling::kGnc}},
                                             o.outliers);
  o.cauchy_scale = node.GetInRange<double>("cauchy_scale", 1e-6, 1e6, o.cauchy_scale);
  o.gnc_threshold = node.GetInRange<double>("gnc_threshold", 0.0, 1e9, o.gnc_threshold);
  o.outlier_confidence =
      node.GetInRange<double>("outlier_confidence", 0.5, 1.0 - 1e-12, o.outlier_confidence);
  o.gnc_step = node.GetInRange<double>("gnc_step", 1.01, 10.0, o.gnc_step);
  o.newton = node.GetEnum<bool>("sesync_solver", {{"newton", true}, {"ceres", false}}, o.newton);
  o.certify = node.GetEnum<bool>("certify", {{"true", true}, {"false", false}}, o.certify);
  o.staircase = node.GetEnum<bool>("staircase", {{"true", true}, {"false", false}}, o.staircase);
  o.dogleg = node.GetEnum<bool>("trust_region", {{"lm", false}, {"dogleg", true}}, o.dogleg);
  o.initial_trust_region_radius = node.GetInRange<double>("initial_trust_region_radius", 1e-6, 1e16,
                                                          o.initial_trust_region_radius);
  o.eigen_sparse =
      node.GetEnum<bool>("sparse_library", {{"auto", false}, {"eigen", true}}, o.eigen_sparse);
  o.jacobi_scaling =
      node.GetEnum<bool>("jacobi_scaling", {{"true", true}, {"false", false}}, o.jacobi_scaling);
  o.max_iterations = node.GetInRange<int>("max_iterations", 1, 100000, o.max_iterations);
  o.num_threads = node.GetInRange<int>("num_threads", 1, 256, o.num_threads);
  o.function_tolerance =
      node.GetInRange<double>("function_tolerance", 0.0, 1.0, o.function_tolerance);
  o.gradient_tolerance =
      node.GetInRange<double>("gradient_tolerance", 0.0, 1.0, o.gradient_tolerance);
  o.parameter_tolerance =
      node.GetInRange<double>("parameter_tolerance", 0.0, 1.0, o.parameter_tolerance);
  return o;
}

double ChiSquaredQuantile(int dof, double p) {
  if (dof < 1 || !(p > 0.0 && p < 1.0)) {
    throw std::invalid_argument("ChiSquaredQuantile: need dof >= 1 and 0 < p < 1");
  }
  return stats::Chi2Quantile(static_cast<double>(dof), p);
}

double InlierThreshold(int dimension, double confidence) {
  return dimension == 2 ? 2.0 * ChiSquaredQuantile(3, confidence)
                        : 4.0 * ChiSquaredQuantile(6, confidence);
}

namespace {

double GncThreshold(const PoseGraph& graph, const PoseGraphSolverOptions& options) {
  return options.gnc_threshold > 0.0 ? options.gnc_threshold
                                     : InlierThreshold(graph.dimension, options.outlier_confidence);
}

// F term of every edge at the current vertex poses.
std::vector<double> EdgeTerms(const PoseGraph& graph) {
  const auto index = VertexIndex(graph);
  std::vector<double> r2(graph.edges.size(), 0.0);
  for (size_t k = 0; k < graph.edges.size(); ++k) {
    const PoseEdge& e = graph.edges[k];
    r2[k] = SeSyncEdgeTerm(e, graph.dimension,
                           graph.vertices[static_cast<size_t>(index.at(e.from))].pose,
                           graph.vertices[static_cast<size_t>(index.at(e.to))].pose);
  }
  return r2;
}

}  // namespace

std::vector<bool> RobustChordalInitialisation(PoseGraph& graph,
                                              const PoseGraphSolverOptions& options, int* steps) {
  // Graduated non-convexity with the Geman-McClure surrogate (Yang et al.
  // 2020) around the chordal relaxation: each step is one weighted linear
  // chordal solve; loop-closure weights w = (mu c^2 / (r^2 + mu c^2))^2 with
  // r^2 the edge's F term; mu shrinks from "almost least squares" to 1.
  // Odometry edges are trusted (weight 1). A weight below 1e-9 is set to
  // exactly 0 so the edge leaves the sparsity pattern (outliers join distant
  // poses and cause most of the fill-in); it is re-evaluated every step.
  CheckGaugeAndFinite(graph);
  const double c2 = GncThreshold(graph, options);
  std::vector<double> weights(graph.edges.size(), 1.0);
  int count = 0;
  ChordalInitialisation(graph, &weights);
  ++count;
  std::vector<double> r2 = EdgeTerms(graph);
  double max_r2 = 0.0;
  for (size_t k = 0; k < r2.size(); ++k) {
    if (IsLoopClosure(graph.edges[k])) max_r2 = std::max(max_r2, r2[k]);
  }
  double mu = std::max(1.0, 2.0 * max_r2 / c2);
  while (true) {
    for (size_t k = 0; k < r2.size(); ++k) {
      if (!IsLoopClosure(graph.edges[k])) continue;
      const double a = mu * c2 / (r2[k] + mu * c2);
      weights[k] = a * a < 1e-9 ? 0.0 : a * a;
    }
    ChordalInitialisation(graph, &weights);
    ++count;
    r2 = EdgeTerms(graph);
    if (mu <= 1.0) break;
    mu = std::max(1.0, mu / options.gnc_step);
  }
  std::vector<bool> inlier(graph.edges.size(), true);
  for (size_t k = 0; k < r2.size(); ++k) {
    if (IsLoopClosure(graph.edges[k])) inlier[k] = weights[k] > 0.5;
  }
  for (size_t k = 0; k < r2.size(); ++k) weights[k] = inlier[k] ? 1.0 : 0.0;
  ChordalInitialisation(graph, &weights);
  ++count;
  if (steps != nullptr) *steps = count;
  return inlier;
}

PoseGraphSolverSummary SolvePoseGraph(PoseGraph& graph, const PoseGraphSolverOptions& options) {
  CheckGaugeAndFinite(graph);
  PoseGraphSolverSummary out;
  out.information = CheckInformation(graph, options.objective);
  const Clock::time_point start = Clock::now();
  const bool file_has_guess = !graph.vertices_implied;
  out.inlier.assign(graph.edges.size(), true);
  if (options.outliers == OutlierHandling::kGnc) {
    out.inlier = RobustChordalInitialisation(graph, options);
  } else
    switch (options.initialisation) {
      case Initialisation::kChordal:
        ChordalInitialisation(graph);
        break;
      case Initialisation::kOdometry:
        OdometryInitialisation(graph);
        break;
      case Initialisation::kFile:
        if (!file_has_guess) OdometryInitialisation(graph);
        break;
    }
  out.init_time_s = Seconds(start);
  const Clock::time_point solve_start = Clock::now();
  for (const PoseEdge& e : graph.edges) out.loop_closures += IsLoopClosure(e) ? 1 : 0;

  bool first = true;
  auto run = [&](Problem& problem, int max_iterations) {
    const ceres::Solver::Summary s = problem.Solve(max_iterations, start);
    if (first) out.initial_cost = s.initial_cost;
    first = false;
    out.iterations += static_cast<int>(s.iterations.size()) - 1;
    out.final_cost = s.final_cost;
    out.converged = s.termination_type == ceres::CONVERGENCE;
    out.message = s.BriefReport();
  };

  if (options.outliers == OutlierHandling::kGnc) {
    // Refine on the edges GNC kept (rejected ones are not in the problem),
    // re-admit near-consistent loop closures (below), then classify every
    // loop closure by its F term (inlier iff below c^2), refine on the
    // inliers, and repeat until the set is stable.
    const double c2 = GncThreshold(graph, options);
    {
      Problem problem(graph, options, &out.inlier);
      run(problem, options.max_iterations);
      problem.FromParameters();
    }
    // Re-admission: the chordal GNC drops some true loop closures (the
    // chordal estimate is only approximate); at the refined, outlier-free
    // estimate they are near-consistent, outliers are not. Candidates are the
    // loop closures whose end-of-schedule GNC weight (c^2 / (r^2 + c^2))^2 is
    // at least 1e-4 (the rest would carry < 1e-4 of an inlier's information;
    // leaving them out keeps the random long-range outliers out of the
    // sparsity pattern). GNC (Geman-McClure on the F terms) then runs again
    // over the candidates, each step a short warm-started nonlinear solve of
    // the weighted F.
    {
      std::vector<double> r2 = EdgeTerms(graph);
      std::vector<bool> candidate(graph.edges.size(), true);
      double max_r2 = 0.0;
      for (size_t k = 0; k < r2.size(); ++k) {
        if (!IsLoopClosure(graph.edges[k])) continue;
        candidate[k] = r2[k] < 99.0 * c2;
        if (candidate[k]) max_r2 = std::max(max_r2, r2[k]);
      }
      PoseGraphSolverOptions sesync = options;
      sesync.objective = Objective::kSeSync;
      std::vector<WeightLoss> weights(graph.edges.size());
      Problem problem(graph, sesync, &candidate, &weights);
      for (double mu = std::max(1.0, 2.0 * max_r2 / c2);;
           mu = std::max(1.0, mu / options.gnc_step)) {
        for (size_t k = 0; k < r2.size(); ++k) {
          const double a = mu * c2 / (r2[k] + mu * c2);
          weights[k].weight = a * a;
        }
        run(problem, 20);
        problem.FromParameters();
        r2 = EdgeTerms(graph);
        if (mu <= 1.0) break;
      }
    }
    for (int round = 0; round < 5; ++round) {
      const std::vector<double> r2 = EdgeTerms(graph);
      out.rejected = 0;
      bool changed = false;
      for (size_t k = 0; k < r2.size(); ++k) {
        if (!IsLoopClosure(graph.edges[k])) continue;
        const bool keep = r2[k] < c2;
        changed = changed || keep != out.inlier[k];
        out.inlier[k] = keep;
        out.rejected += keep ? 0 : 1;
      }
      if (!changed && round > 0) break;
      Problem problem(graph, options, &out.inlier);
      run(problem, options.max_iterations);
      problem.FromParameters();
    }
  } else if (options.newton && options.objective == Objective::kSeSync &&
             options.outliers == OutlierHandling::kNone) {
    SeSyncNewtonOptions newton;
    newton.max_iterations = options.max_iterations;
    if (options.progress) {
      newton.progress = [&](int iteration, double cost, double) {
        options.progress(iteration, cost, Seconds(start));
      };
    }
    const SeSyncNewtonSummary s = SolveSeSyncNewton(graph, newton);
    out.iterations = s.iterations;
    out.initial_cost = s.initial_cost;
    out.final_cost = s.final_cost;
    out.converged = s.converged;
    std::ostringstream message;
    message << "Newton (exact Hessian): " << s.iterations << " iterations, " << s.factorisations
            << " factorisations, " << s.message << ", gradient max-norm " << s.gradient_max_norm;
    out.message = message.str();
  } else {
    Problem problem(graph, options);
    run(problem, options.max_iterations);
    if (options.outliers == OutlierHandling::kCauchy) {
      // Classify: a loop closure is rejected if its Cauchy weight fell below
      // 1/10, i.e. |r|^2 > 9 c^2.
      const std::vector<double> r2 = problem.SquaredResiduals();
      const double c2 = options.cauchy_scale * options.cauchy_scale;
      for (size_t k = 0; k < r2.size(); ++k) {
        if (IsLoopClosure(graph.edges[k]) && r2[k] > 9.0 * c2) {
          out.inlier[k] = false;
          ++out.rejected;
        }
      }
    }
    problem.FromParameters();
  }
  out.solve_time_s = Seconds(solve_start);
  out.F = SeSyncObjective(graph);
  if (options.certify && options.objective == Objective::kSeSync &&
      options.outliers == OutlierHandling::kNone) {
    const SeSyncRelaxation relaxation(graph);
    out.certificate = relaxation.Certify(relaxation.Rotations(graph), out.F, options.certificate);
    if (!out.certificate->certified && options.staircase) {
      // A critical point that is not the global optimum: climb, round,
      // refine at rank d and certify the result.
      SeSyncStaircaseOptions staircase;
      staircase.certificate = options.certificate;
      const SeSyncStaircaseSummary climb = ClimbSeSyncStaircase(graph, *out.certificate, staircase);
      out.staircase_rank = climb.rank;
      out.staircase_iterations = climb.iterations;
      SeSyncNewtonOptions newton;
      newton.max_iterations = options.max_iterations;
      newton.gauss_newton_steps = 0;  // Rounded from the relaxation: near the optimum.
      const SeSyncNewtonSummary refined = SolveSeSyncNewton(graph, newton);
      out.iterations += refined.iterations;
      out.final_cost = refined.final_cost;
      out.converged = refined.converged;
      out.F = SeSyncObjective(graph);
      out.certificate = relaxation.Certify(relaxation.Rotations(graph), out.F, options.certificate);
    }
  }
  out.total_time_s = Seconds(start);
  out.chi2 = Chi2Objective(graph);
  return out;
}

}  // namespace rover::mapping
