// bench_graph: time to converge on the standard pose-graph datasets, next to
// the published SE-Sync optima and GTSAM times; optionally the outlier study.
//
// usage: bench_graph [--data DIR] [--outliers]
//   DIR defaults to $ROVER_SHARED_DIR/data/posegraph (or the configured one).

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "mapping/graph/g2o_reader.h"
#include "mapping/graph/outlier_injection.h"
#include "mapping/graph/pose_graph_solver.h"
#include "mapping/graph/se_sync_objective.h"

namespace {

using rover::mapping::Objective;
using rover::mapping::OutlierHandling;
using rover::mapping::PoseGraph;
using rover::mapping::PoseGraphSolverOptions;
using rover::mapping::PoseGraphSolverSummary;

struct Dataset {
  const char* file;
  double published_F;
  double gtsam_s;
};

constexpr Dataset kDatasets[] = {{"sphere2500.g2o", 1.687e3, 0.704},
                                 {"parking-garage.g2o", 1.263e0, 0.415},
                                 {"manhattan.g2o", 6.432e3, 0.268},
                                 {"intel.g2o", 5.235e1, 0.120},
                                 {"CSAIL.g2o", 3.170e1, 0.029}};

void Solve(const std::string& dir, const Dataset& d) {
  const PoseGraph original = rover::mapping::ReadG2oFile(dir + "/" + d.file);
  for (const Objective objective : {Objective::kSeSync, Objective::kChi2}) {
    PoseGraph g = original;
    PoseGraphSolverOptions o;
    o.objective = objective;
    const PoseGraphSolverSummary s = rover::mapping::SolvePoseGraph(g, o);
    const bool sesync = objective == Objective::kSeSync;
    std::printf("%-20s %-7s iters %3d  init %6.3f s  total %6.3f s  (GTSAM PDL %5.3f s)  F %.6e",
                d.file, sesync ? "sesync" : "chi2", s.iterations, s.init_time_s, s.total_time_s,
                d.gtsam_s, s.F);
    if (sesync) {
      std::printf("  published %.3e  rel %.1e", d.published_F,
                  std::abs(s.F - d.published_F) / d.published_F);
    } else {
      std::printf("  chi2 %.6e", s.chi2);
    }
    std::printf("\n");
  }
}

void Outliers(const std::string& dir, const char* file, double fraction) {
  const PoseGraph clean = rover::mapping::ReadG2oFile(dir + "/" + file);
  PoseGraphSolverOptions o;
  o.objective = Objective::kSeSync;
  PoseGraph reference = clean;
  const double F0 = rover::mapping::SolvePoseGraph(reference, o).F;
  for (const OutlierHandling handling : {OutlierHandling::kCauchy, OutlierHandling::kGnc}) {
    PoseGraph g = clean;
    const size_t inliers = g.edges.size();
    const int injected = rover::mapping::InjectFalseLoopClosures(g, fraction, 1);
    o.outliers = handling;
    const PoseGraphSolverSummary s = rover::mapping::SolvePoseGraph(g, o);
    std::vector<bool> mask(g.edges.size(), false);
    int false_rejected = 0;
    int true_rejected = 0;
    for (size_t k = 0; k < g.edges.size(); ++k) {
      mask[k] = k < inliers;
      if (!s.inlier[k]) (k < inliers ? true_rejected : false_rejected) += 1;
    }
    const double F = rover::mapping::SeSyncObjective(g, &mask);
    std::printf(
        "%-16s %3.0f%% %-6s injected %4d  rejected %4d (outliers %4d, true loops %3d)  "
        "F(inlier edges) %.6e vs outlier-free %.6e  (%+.2f%%)  %.1f s\n",
        file, 100.0 * fraction, handling == OutlierHandling::kGnc ? "gnc" : "cauchy", injected,
        s.rejected, false_rejected, true_rejected, F, F0, 100.0 * (F - F0) / F0, s.total_time_s);
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::string dir;
  if (const char* env = std::getenv("ROVER_SHARED_DIR")) dir = std::string(env) + "/data/posegraph";
  if (dir.empty()) dir = ROVER_GRAPH_BENCH_DATA;
  bool outliers = false;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--data") == 0 && i + 1 < argc) {
      dir = argv[++i];
    } else if (std::strcmp(argv[i], "--outliers") == 0) {
      outliers = true;
    } else {
      std::fprintf(stderr, "usage: bench_graph [--data DIR] [--outliers]\n");
      return 2;
    }
  }
  try {
    std::printf("== Pose graph: time to converge (chordal init + LM, SuiteSparse, 2 threads)\n");
    for (const Dataset& d : kDatasets) Solve(dir, d);
    if (outliers) {
      std::printf("\n== Pose graph: random false loop closures (seeded)\n");
      for (const char* file : {"manhattan.g2o", "sphere2500.g2o"}) {
        for (const double fraction : {0.1, 0.3}) Outliers(dir, file, fraction);
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_graph: %s\n", e.what());
    return 1;
  }
  return 0;
}
