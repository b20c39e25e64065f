// The incremental pose-graph solver: its partial re-factorisation against a
// full one on identical linear systems, RoverGraph's incremental updates
// against full Ceres solves on seeded synthetic submap sequences with loop
// closures, the cost of a local loop closure, the marginals near a change,
// and option validation.

#include <gtest/gtest.h>

#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/geometry/so3.h"
#include "core/geometry/yaw.h"
#include "mapping/graph/incremental_pose_solver.h"
#include "mapping/graph/pose_manifold.h"
#include "mapping/graph/rover_graph.h"
#include "mapping/graph/synthetic_submap_trajectory.h"
#include "tests/mapping/graph/incremental_agreement.h"

namespace rover::mapping {
namespace {

using Vector6 = Eigen::Matrix<double, 6, 1>;

Eigen::Isometry3d RandomPose(std::mt19937& rng, double sigma_p, double sigma_r) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = sigma_p * Eigen::Vector3d(n(rng), n(rng), n(rng));
  T.linear() = ExpSO3(sigma_r * Eigen::Vector3d(n(rng), n(rng), n(rng)));
  return T;
}

// With relinearisation disabled both solvers solve the same linear systems;
// one re-factors only the columns each update reaches (fixed ordering,
// appended variables), the other re-orders and re-factors everything. Their
// solutions and marginals must agree to round-off after every update.
TEST(IncrementalPoseSolverTest, PartialRefactorisationMatchesFullRefactorisation) {
  std::mt19937 rng(3);
  IncrementalPoseSolverOptions partial_options;
  partial_options.relinearize_rotation_rad = 1.0;
  partial_options.relinearize_translation_m = 100.0;
  partial_options.robust_weight_tolerance = 1e9;
  partial_options.reorder_interval = 60;
  IncrementalPoseSolverOptions full_options = partial_options;
  full_options.reorder_interval = 0;
  IncrementalPoseSolver partial(partial_options), full(full_options);
  const Matrix6d information = 100.0 * Matrix6d::Identity();
  std::vector<Eigen::Isometry3d> truth = {Eigen::Isometry3d::Identity()};
  std::array<double, 7> x;
  PoseToParameters(truth[0], x.data());
  for (IncrementalPoseSolver* s : {&partial, &full}) {
    s->AddVariable(x.data());
    s->AddFactor(0, -1, truth[0], 1e6 * Matrix6d::Identity(), false);
  }
  for (int i = 1; i < 240; ++i) {
    const Eigen::Isometry3d step = RandomPose(rng, 0.5, 0.1);
    truth.push_back(truth.back() * step);
    // Start away from the truth so that the solution is not trivial.
    PoseToParameters(truth.back() * RandomPose(rng, 0.05, 0.01), x.data());
    const Eigen::Isometry3d odometry = step * RandomPose(rng, 0.02, 0.002);
    std::vector<std::pair<int, Eigen::Isometry3d>> loops;
    if (i % 7 == 0 && i > 20) {
      const int j = std::uniform_int_distribution<int>(0, i - 10)(rng);
      loops.emplace_back(
          j, truth[static_cast<size_t>(j)].inverse() * truth.back() * RandomPose(rng, 0.02, 0.002));
    }
    for (IncrementalPoseSolver* s : {&partial, &full}) {
      s->AddVariable(x.data());
      s->AddFactor(i - 1, i, odometry, information, false);
      for (const auto& [j, T] : loops) s->AddFactor(j, i, T, information, false);
    }
    if (i % 5 != 0) continue;
    const IncrementalPoseSolverStats sp = partial.Update();
    full.Update();
    ASSERT_TRUE(sp.converged);
    for (int v = 0; v <= i; ++v) {
      std::array<double, 7> a, b;
      partial.Estimate(v, a.data());
      full.Estimate(v, b.data());
      for (int c = 0; c < 7; ++c) {
        EXPECT_NEAR(a[static_cast<size_t>(c)], b[static_cast<size_t>(c)], 1e-9)
            << "variable " << v << " after " << i;
      }
    }
    for (const int v : {0, i / 2, i}) {
      const Matrix6d ca = partial.MarginalCovariance(v);
      const Matrix6d cb = full.MarginalCovariance(v);
      EXPECT_LT((ca - cb).norm(), 1e-9 * cb.norm()) << "variable " << v << " after " << i;
    }
  }
}

// iSAM2-style updates (one Gauss-Newton step each) leave part of the
// convergence to later updates; Converge() finishes it. With thresholds that
// relinearise every move, both end at the same optimum as updates that
// converge every time.
TEST(IncrementalPoseSolverTest, OneStepUpdatesThenConvergeReachTheConvergedSolution) {
  std::mt19937 rng(5);
  IncrementalPoseSolverOptions converging_options;
  converging_options.relinearize_rotation_rad = 0.0;
  converging_options.relinearize_translation_m = 0.0;
  converging_options.max_iterations = 50;
  IncrementalPoseSolverOptions one_step_options = converging_options;
  one_step_options.steps_per_update = 1;
  IncrementalPoseSolver converging(converging_options), one_step(one_step_options);
  const Matrix6d information = 100.0 * Matrix6d::Identity();
  std::vector<Eigen::Isometry3d> truth = {Eigen::Isometry3d::Identity()};
  std::array<double, 7> x;
  PoseToParameters(truth[0], x.data());
  for (IncrementalPoseSolver* s : {&converging, &one_step}) {
    s->AddVariable(x.data());
    s->AddFactor(0, -1, truth[0], 1e6 * Matrix6d::Identity(), false);
  }
  int unconverged_steps = 0;
  for (int i = 1; i < 120; ++i) {
    const Eigen::Isometry3d step = RandomPose(rng, 0.5, 0.1);
    truth.push_back(truth.back() * step);
    const Eigen::Isometry3d odometry = step * RandomPose(rng, 0.02, 0.002);
    // Loops a few steps back: inliers of the Cauchy loss.
    const int j = std::max(0, i - std::uniform_int_distribution<int>(3, 8)(rng));
    const Eigen::Isometry3d loop =
        truth[static_cast<size_t>(j)].inverse() * truth.back() * RandomPose(rng, 0.02, 0.002);
    for (IncrementalPoseSolver* s : {&converging, &one_step}) {
      // Initialised by odometry from the current estimate, as RoverGraph does.
      s->Estimate(i - 1, x.data());
      PoseToParameters(PoseFromParameters(x.data()) * odometry, x.data());
      s->AddVariable(x.data());
      s->AddFactor(i - 1, i, odometry, information, false);
      if (i % 6 == 0) s->AddFactor(j, i, loop, information, true);
    }
    if (i % 3 != 0) continue;
    ASSERT_TRUE(converging.Update().converged);
    const IncrementalPoseSolverStats stats = one_step.Update();
    EXPECT_EQ(stats.iterations, 1);
    unconverged_steps += stats.converged ? 0 : 1;
  }
  EXPECT_GT(unconverged_steps, 0);  // the one-step updates did leave work
  ASSERT_TRUE(one_step.Converge().converged);
  for (int v = 0; v < converging.num_variables(); ++v) {
    std::array<double, 7> a, b;
    converging.Estimate(v, a.data());
    one_step.Estimate(v, b.data());
    const Eigen::Isometry3d A = PoseFromParameters(a.data());
    const Eigen::Isometry3d B = PoseFromParameters(b.data());
    EXPECT_LT((A.translation() - B.translation()).norm(), 1e-6) << "variable " << v;
    EXPECT_LT(LogSO3(A.linear().transpose() * B.linear()).norm(), 1e-6) << "variable " << v;
  }
}

// The periodic re-ordering (a full re-factorisation) is done on updates that
// only extend the graph, never on a loop-closing update, once the solver runs.
TEST(IncrementalGraphTest, ReorderingHappensOnExtensionUpdates) {
  SyntheticSubmapTrajectoryOptions so;
  so.submaps = 200;
  const SyntheticSubmapTrajectory traj = MakeSyntheticSubmapTrajectory(so, 4);
  RoverGraph graph;
  traj.AddPrior(&graph);
  graph.Optimize();
  int reorders = 0, incremental_loop_updates = 0;
  for (size_t i = 0; i < traj.steps.size(); ++i) {
    const int loops = traj.AddStep(i, &graph);
    const RoverGraphSummary s = graph.Optimize();
    if (s.reordered) {
      ++reorders;
      EXPECT_FALSE(s.solved) << "update " << i;
      EXPECT_EQ(loops, 0) << "update " << i;
      EXPECT_EQ(s.refactored_columns, s.variables) << "update " << i;
    }
    if (loops > 0 && s.incremental_solve) ++incremental_loop_updates;
  }
  // 2 variables per submap, re-ordered every 100: one per 50 submaps.
  EXPECT_GE(reorders, 3);
  EXPECT_GT(incremental_loop_updates, 10);
}

// After every update of seeded 300-submap sequences (frame switches, filter
// poses, loop closures every few submaps), all origins agree with full Ceres
// solves within 1 mm / 0.01 deg, and every loop closure was incremental.
TEST(IncrementalGraphTest, EveryUpdateAgreesWithTheFullSolveOverSeeds) {
  for (const uint32_t seed : {1u, 2u, 3u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const AgreementResult r = RunAgainstFullSolves(300, seed);
    EXPECT_GT(r.loop_updates, 15);
    EXPECT_EQ(r.incremental_solves, r.loop_updates);
    std::printf("seed %u: max gap %.4f mm, %.5f deg over %d loop closures\n", seed,
                1e3 * r.max_translation_m, r.max_rotation_rad * 180.0 / 3.14159265358979,
                r.loop_updates);
  }
}

// mapd's way (one Gauss-Newton step per update, relinearisation above 2 mrad
// or 5 mm, the rest of the convergence in idle time): once the idle-time
// steps are done, every origin is within 5 mm and 0.02 deg of the full
// solve. A loop closure's single step leaves the graph unconverged, and
// Refine() is what finishes it.
TEST(IncrementalGraphTest, OneStepUpdatesRefinedInIdleTimeAgreeWithTheFullSolve) {
  AgreementSetup setup;
  setup.incremental_options = RoverGraphOptions::Online();
  setup.refine = true;
  setup.tolerance_m = 5e-3;
  setup.tolerance_rad = 0.02 * 3.14159265358979 / 180.0;
  for (const uint32_t seed : {2u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const AgreementResult r = RunAgainstFullSolves(200, seed, setup);
    EXPECT_GE(r.loop_updates, 10);
    EXPECT_GT(r.unconverged_updates, 0);
    EXPECT_GE(r.refinement_steps, r.unconverged_updates);
    std::printf("seed %u: max gap %.4f mm, %.5f deg; %d of %d loop closures needed %d steps\n",
                seed, 1e3 * r.max_translation_m, r.max_rotation_rad * 180.0 / 3.14159265358979,
                r.unconverged_updates, r.loop_updates, r.refinement_steps);
  }
  // Without a due step, Refine() does nothing and says converged.
  RoverGraph idle;
  SyntheticSubmapTrajectoryOptions so;
  so.submaps = 5;
  MakeSyntheticSubmapTrajectory(so, 1).AddPrior(&idle);
  idle.Optimize();
  EXPECT_FALSE(idle.NeedsRefinement());
  const RoverGraphSummary s = idle.Refine();
  EXPECT_TRUE(s.converged);
  EXPECT_FALSE(s.solved);
}

// A loop closed between two of the newest submaps of a long chain changes
// only that cycle: the update relinearises and re-factors a small part of
// the graph, and the marginals near it match a batch solve.
TEST(IncrementalGraphTest, LocalLoopClosureCostsWhatChanged) {
  SyntheticSubmapTrajectoryOptions so;
  so.submaps = 400;
  so.loop_every = 0;  // no loops while the chain grows
  const SyntheticSubmapTrajectory traj = MakeSyntheticSubmapTrajectory(so, 7);
  RoverGraph incremental;
  RoverGraphOptions batch_options;  // the same solver, everything every time
  batch_options.relinearize_rotation_rad = 0.0;
  batch_options.relinearize_translation_m = 0.0;
  batch_options.reorder_interval = 0;
  batch_options.covariance_hops = -1;
  RoverGraph batch(batch_options);
  for (RoverGraph* g : {&incremental, &batch}) {
    traj.AddPrior(g);
    g->Optimize();
    for (size_t i = 0; i < traj.steps.size(); ++i) {
      traj.AddStep(i, g);
      g->Optimize();
    }
  }
  const int64_t last = traj.steps.back().submap;
  const Eigen::Isometry3d T_a_b = traj.T_world_origin[static_cast<size_t>(last - 4)].inverse() *
                                  traj.T_world_origin[static_cast<size_t>(last)];
  Vector6 sigma;
  sigma << 0.05, 0.05, 0.05, 0.005, 0.005, 0.005;
  RoverGraphSummary s_inc, s_batch;
  for (RoverGraph* g : {&incremental, &batch}) {
    g->AddSubmapMatch(0, last - 4, 0, last, T_a_b, Matrix6d(sigma.cwiseAbs2().asDiagonal()));
  }
  s_inc = incremental.Optimize();
  s_batch = batch.Optimize();
  ASSERT_TRUE(s_inc.incremental_solve);
  EXPECT_LT(s_inc.relinearized, s_inc.variables / 10);
  // Per Gauss-Newton iteration, a quarter of the factor at most (the batch
  // re-factors all of it).
  EXPECT_LT(s_inc.refactored_columns, s_inc.iterations * s_inc.variables / 4);
  EXPECT_GE(s_batch.refactored_columns, s_batch.iterations * (s_batch.variables - 1));
  EXPECT_LT(s_inc.covariances_updated, 20);
  for (int64_t k = last - 6; k <= last; ++k) {
    const Matrix6d a = incremental.OriginCovariance(0, k);
    const Matrix6d b = batch.OriginCovariance(0, k);
    EXPECT_LT((a - b).norm(), 1e-2 * b.norm()) << "s0_" << k;
    EXPECT_LT((incremental.Origin(0, k).translation() - batch.Origin(0, k).translation()).norm(),
              kAgreementTranslationM);
  }
}

TEST(IncrementalGraphTest, InvalidOptionsNameTheKey) {
  const auto message = [](const RoverGraphOptions& o) {
    try {
      RoverGraph g(o);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  RoverGraphOptions o;
  o.reorder_interval = -1;
  EXPECT_NE(message(o).find("reorder_interval"), std::string::npos) << message(o);
  o = {};
  o.relinearize_rotation_rad = -0.1;
  EXPECT_NE(message(o).find("relinearize_rotation_rad"), std::string::npos) << message(o);
  o = {};
  o.covariance_hops = -2;
  EXPECT_NE(message(o).find("covariance_hops"), std::string::npos) << message(o);
  o = {};
  o.incremental_steps = -1;
  EXPECT_NE(message(o).find("incremental_steps"), std::string::npos) << message(o);
  EXPECT_EQ(message(RoverGraphOptions{}), "no error");
}

}  // namespace
}  // namespace rover::mapping
