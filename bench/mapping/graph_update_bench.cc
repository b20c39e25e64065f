// Online pose-graph updates (RoverGraph, as mapd's SlamWorker runs them) on a
// synthetic 1000-submap rover sequence with loop closures: per-update time of
// the incremental solver (fluid relinearisation, partial re-factorisation,
// origin marginals near the change) against a full re-solve of the whole
// graph with the same solver in the same run (every variable relinearised,
// re-ordered and re-factored at every update, all origin marginals), and
// optionally against the Ceres full solve. Agreement: after every update, the
// largest origin difference between the incremental and the full solution.
// Updates that only extend the graph (no loop) need no solve on either side
// but carry the incremental solver's periodic re-ordering: their times are
// reported separately. The targets are stated at the full size, so the
// loop updates of the last tenth of the sequence (900-1000 submaps by
// default) are also reported on their own: there both sides work on the
// graph the targets name, where the all-sizes figures mix in small graphs
// whose fixed costs dominate.
//
//   bench_graph_update [--submaps N] [--first-seed S] [--seeds K] [--loop-every N]
//                      [--relinearize-rotation-rad X] [--relinearize-translation-m X]
//                      [--w-sigma-p-m X] [--w-sigma-yaw-rad X] [--steps N] [--ceres]
//                      [--verbose]

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "core/geometry/so3.h"
#include "core/stats/percentile.h"
#include "mapping/graph/rover_graph.h"
#include "mapping/graph/synthetic_submap_trajectory.h"

namespace rover::mapping {
namespace {

double TimedOptimize(RoverGraph* graph, RoverGraphSummary* summary) {
  const auto start = std::chrono::steady_clock::now();
  *summary = graph->Optimize();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

struct Gap {
  double translation_m = 0.0;
  double rotation_rad = 0.0;
};

Gap OriginGap(const RoverGraph& a, const RoverGraph& b, int64_t submaps) {
  Gap gap;
  for (int64_t k = 0; k < submaps; ++k) {
    const Eigen::Isometry3d A = a.Origin(0, k);
    const Eigen::Isometry3d B = b.Origin(0, k);
    gap.translation_m = std::max(gap.translation_m, (A.translation() - B.translation()).norm());
    gap.rotation_rad =
        std::max(gap.rotation_rad, LogSO3(A.linear().transpose() * B.linear()).norm());
  }
  return gap;
}

struct Args {
  int submaps = 1000;
  int first_seed = 1;
  int seeds = 3;
  int loop_every = 5;
  // mapd's settings unless told otherwise.
  double relinearize_rotation_rad = RoverGraphOptions::Online().relinearize_rotation_rad;
  double relinearize_translation_m = RoverGraphOptions::Online().relinearize_translation_m;
  int steps = RoverGraphOptions::Online().incremental_steps;
  bool ceres = false;
  bool verbose = false;
  double w_sigma_p_m = SyntheticSubmapTrajectoryOptions{}.w_sigma_p_m;
  double w_sigma_yaw_rad = SyntheticSubmapTrajectoryOptions{}.w_sigma_yaw_rad;
};

Args Parse(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string s = argv[i];
    const auto next = [&]() -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s: expected a value\n", s.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (s == "--submaps") {
      a.submaps = std::atoi(next());
    } else if (s == "--first-seed") {
      a.first_seed = std::atoi(next());
    } else if (s == "--seeds") {
      a.seeds = std::atoi(next());
    } else if (s == "--loop-every") {
      a.loop_every = std::atoi(next());
    } else if (s == "--relinearize-rotation-rad") {
      a.relinearize_rotation_rad = std::atof(next());
    } else if (s == "--relinearize-translation-m") {
      a.relinearize_translation_m = std::atof(next());
    } else if (s == "--w-sigma-p-m") {
      a.w_sigma_p_m = std::atof(next());
    } else if (s == "--w-sigma-yaw-rad") {
      a.w_sigma_yaw_rad = std::atof(next());
    } else if (s == "--steps") {
      a.steps = std::atoi(next());
    } else if (s == "--verbose") {
      a.verbose = true;
    } else if (s == "--ceres") {
      a.ceres = true;
    } else {
      std::fprintf(stderr, "unknown argument %s\n", s.c_str());
      std::exit(2);
    }
  }
  return a;
}

int Run(const Args& args) {
  std::printf(
      "seed loops | incremental ms p50 p99 max (cov p99) | full same solver ms p50 p99 max | "
      "ratio p50 p99 | gap max mm deg | cov rel gap near / stale-PSD min eig | "
      "extension updates ms p99 max | solve-only ratio p50 p99%s\n",
      args.ceres ? " | ceres full ms p50 p99" : "");
  std::vector<double> ratio_p50, ratio_p99, gap_mm, large_p50, large_p99, large_inc_p99;
  for (int seed = args.first_seed; seed < args.first_seed + args.seeds; ++seed) {
    SyntheticSubmapTrajectoryOptions so;
    so.submaps = args.submaps;
    so.loop_every = args.loop_every;
    so.w_sigma_p_m = args.w_sigma_p_m;
    so.w_sigma_yaw_rad = args.w_sigma_yaw_rad;
    const SyntheticSubmapTrajectory traj =
        MakeSyntheticSubmapTrajectory(so, static_cast<uint32_t>(seed));
    RoverGraphOptions inc_options;
    inc_options.relinearize_rotation_rad = args.relinearize_rotation_rad;
    inc_options.relinearize_translation_m = args.relinearize_translation_m;
    RoverGraphOptions full_options = inc_options;  // the same solver as a batch
    inc_options.incremental_steps = args.steps;
    full_options.incremental_steps = 0;  // to convergence
    full_options.relinearize_rotation_rad = 0.0;
    full_options.relinearize_translation_m = 0.0;
    full_options.reorder_interval = 0;
    full_options.covariance_hops = -1;
    RoverGraphOptions ceres_options;
    ceres_options.incremental_solve = false;
    RoverGraph inc(inc_options), full(full_options), ceres(ceres_options);
    std::vector<RoverGraph*> graphs = {&inc, &full};
    if (args.ceres) graphs.push_back(&ceres);
    for (RoverGraph* g : graphs) {
      traj.AddPrior(g);
      g->Optimize();
    }
    std::vector<double> t_inc, t_full, t_ceres, t_cov, t_ext, t_inc_solve, t_full_solve;
    std::vector<double> t_inc_large, t_full_large;  // the last tenth of the sequence
    const int64_t large_from = args.submaps - args.submaps / 10;
    Gap worst;
    for (size_t i = 0; i < traj.steps.size(); ++i) {
      int loops = 0;
      for (RoverGraph* g : graphs) loops = traj.AddStep(i, g);
      RoverGraphSummary s_inc, s_full, s_ceres;
      const double ti = TimedOptimize(&inc, &s_inc);
      const double tf = TimedOptimize(&full, &s_full);
      if (loops == 0) {
        // Extensions: no solve on either side, except the incremental
        // solver's periodic re-ordering, done on them.
        t_ext.push_back(ti);
        continue;
      }
      t_inc.push_back(ti);
      t_full.push_back(tf);
      if (traj.steps[i].submap >= large_from) {
        t_inc_large.push_back(ti);
        t_full_large.push_back(tf);
      }
      // The solves alone: the batch also recomputes every origin marginal,
      // the incremental update only those near the change.
      t_inc_solve.push_back(1e3 * s_inc.solve_time_s);
      t_full_solve.push_back(1e3 * s_full.solve_time_s);
      t_cov.push_back(1e3 * s_inc.covariance_time_s);
      if (args.verbose) {
        std::printf(
            "  submap %4lld: incremental %7.2f ms (%s, %d it, %d relinearised, %d columns of %d, "
            "%d marginals; solver %.2f ms, marginals %.2f ms) full %7.2f ms\n",
            static_cast<long long>(traj.steps[i].submap), ti,
            s_inc.incremental_solve ? "incremental" : "CERES fallback", s_inc.iterations,
            s_inc.relinearized, s_inc.refactored_columns, s_inc.variables,
            s_inc.covariances_updated, 1e3 * s_inc.solve_time_s, 1e3 * s_inc.covariance_time_s, tf);
      }
      if (args.ceres) t_ceres.push_back(TimedOptimize(&ceres, &s_ceres));
      const Gap gap = OriginGap(inc, full, traj.steps[i].submap + 1);
      if (args.verbose) {
        std::printf("    gap %.3f mm %.5f deg\n", 1e3 * gap.translation_m,
                    gap.rotation_rad * 180.0 / 3.14159265358979);
      }
      worst.translation_m = std::max(worst.translation_m, gap.translation_m);
      worst.rotation_rad = std::max(worst.rotation_rad, gap.rotation_rad);
    }
    // Marginals at the end: recomputed ones (near the last change) against
    // the full solver's exact ones, and how far below the exact ones any
    // stale marginal is (negative = not an upper bound).
    double near_gap = 0.0, stale_min_eig = 1e9;
    const int64_t last = traj.steps.back().submap;
    for (int64_t k = 0; k <= last; ++k) {
      const Matrix6d a = inc.OriginCovariance(0, k);
      const Matrix6d b = full.OriginCovariance(0, k);
      const double rel = (a - b).norm() / b.norm();
      if (k >= last - 2) near_gap = std::max(near_gap, rel);
      const Eigen::SelfAdjointEigenSolver<Matrix6d> es(0.5 * (a - b + (a - b).transpose()));
      stale_min_eig = std::min(stale_min_eig, es.eigenvalues()(0) / b.norm());
    }
    const double r50 = stats::Percentile(t_full, 50.0) / stats::Percentile(t_inc, 50.0);
    const double r99 = stats::Percentile(t_full, 99.0) / stats::Percentile(t_inc, 99.0);
    ratio_p50.push_back(r50);
    ratio_p99.push_back(r99);
    gap_mm.push_back(1e3 * worst.translation_m);
    std::printf(
        "%4d %5zu | %6.2f %6.2f %6.2f (%5.2f) | %7.2f %7.2f %7.2f | %5.1f %5.1f | %6.3f %6.4f | "
        "%.1e / %.1e | %5.2f %5.2f | %4.1f %4.1f",
        seed, t_inc.size(), stats::Percentile(t_inc, 50.0), stats::Percentile(t_inc, 99.0),
        stats::Percentile(t_inc, 100.0), stats::Percentile(t_cov, 99.0),
        stats::Percentile(t_full, 50.0), stats::Percentile(t_full, 99.0),
        stats::Percentile(t_full, 100.0), r50, r99, 1e3 * worst.translation_m,
        worst.rotation_rad * 180.0 / 3.14159265358979, near_gap, stale_min_eig,
        stats::Percentile(t_ext, 99.0), stats::Percentile(t_ext, 100.0),
        stats::Percentile(t_full_solve, 50.0) / stats::Percentile(t_inc_solve, 50.0),
        stats::Percentile(t_full_solve, 99.0) / stats::Percentile(t_inc_solve, 99.0));
    if (args.ceres) {
      std::printf(" | %7.1f %7.1f", stats::Percentile(t_ceres, 50.0),
                  stats::Percentile(t_ceres, 99.0));
    }
    std::printf("\n");
    if (!t_inc_large.empty()) {
      const double l50 =
          stats::Percentile(t_full_large, 50.0) / stats::Percentile(t_inc_large, 50.0);
      const double l99 =
          stats::Percentile(t_full_large, 99.0) / stats::Percentile(t_inc_large, 99.0);
      large_p50.push_back(l50);
      large_p99.push_back(l99);
      large_inc_p99.push_back(stats::Percentile(t_inc_large, 99.0));
      std::printf(
          "     at %lld-%d submaps, %zu loop updates: incremental ms p50 %.2f p99 %.2f | full ms "
          "p50 %.2f p99 %.2f | ratio p50 %.1f p99 %.1f\n",
          static_cast<long long>(large_from), args.submaps, t_inc_large.size(),
          stats::Percentile(t_inc_large, 50.0), stats::Percentile(t_inc_large, 99.0),
          stats::Percentile(t_full_large, 50.0), stats::Percentile(t_full_large, 99.0), l50, l99);
    }
    std::fflush(stdout);
  }
  std::printf("spread over seeds: ratio p50 %.1f-%.1f, ratio p99 %.1f-%.1f, gap %.3f-%.3f mm\n",
              *std::min_element(ratio_p50.begin(), ratio_p50.end()),
              *std::max_element(ratio_p50.begin(), ratio_p50.end()),
              *std::min_element(ratio_p99.begin(), ratio_p99.end()),
              *std::max_element(ratio_p99.begin(), ratio_p99.end()),
              *std::min_element(gap_mm.begin(), gap_mm.end()),
              *std::max_element(gap_mm.begin(), gap_mm.end()));
  if (!large_p50.empty()) {
    std::printf(
        "spread over seeds at %d-%d submaps: incremental p99 %.2f-%.2f ms, ratio p50 %.1f-%.1f, "
        "ratio p99 %.1f-%.1f\n",
        args.submaps - args.submaps / 10, args.submaps,
        *std::min_element(large_inc_p99.begin(), large_inc_p99.end()),
        *std::max_element(large_inc_p99.begin(), large_inc_p99.end()),
        *std::min_element(large_p50.begin(), large_p50.end()),
        *std::max_element(large_p50.begin(), large_p50.end()),
        *std::min_element(large_p99.begin(), large_p99.end()),
        *std::max_element(large_p99.begin(), large_p99.end()));
  }
  return 0;
}

}  // namespace
}  // namespace rover::mapping

int main(int argc, char** argv) { return rover::mapping::Run(rover::mapping::Parse(argc, argv)); }
