// bench_graph: time to reach (and, for the SE-Sync objective, certify) the
// optimum on the standard pose-graph datasets, next to the published SE-Sync
// optima and GTSAM times; optionally Helmert blocking and the outlier study.
//
// usage: bench_graph [--data DIR] [--outliers] [--helmert] [--outlier-case FILE FRACTION]
//   DIR defaults to $ROVER_SHARED_DIR/data/posegraph (or the configured one).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "mapping/graph/chordal_initialisation.h"
#include "mapping/graph/g2o_reader.h"
#include "mapping/graph/helmert_block_solver.h"
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

// Every standard dataset of the folder (published F* where the posegraph
// README has one, else 0).
constexpr Dataset kAllDatasets[] = {
    {"sphere2500.g2o", 1.687e3, 0.704}, {"parking-garage.g2o", 1.263e0, 0.415},
    {"manhattan.g2o", 6.432e3, 0.268},  {"intel.g2o", 5.235e1, 0.120},
    {"CSAIL.g2o", 3.170e1, 0.029},      {"kitti_00.g2o", 0.0, 0.0},
    {"smallGrid3D.g2o", 0.0, 0.0},      {"tinyGrid3D.g2o", 0.0, 0.0}};

struct CertifiedRun {
  PoseGraphSolverSummary summary;
  double min_s = 0.0;     // Fastest of the repeats.
  double median_s = 0.0;  // Median of the repeats.
  double max_s = 0.0;
};

// `repeats` solves of the SE-Sync objective from the file, each certified.
CertifiedRun RunSeSync(const PoseGraph& original, bool newton, int repeats) {
  CertifiedRun run;
  std::vector<double> times;
  for (int k = 0; k < repeats; ++k) {
    PoseGraph g = original;
    PoseGraphSolverOptions o;
    o.objective = Objective::kSeSync;
    o.newton = newton;
    // The reference is the Ceres pipeline as it was: its certificate is
    // reported, not repaired by the staircase.
    o.staircase = newton;
    run.summary = rover::mapping::SolvePoseGraph(g, o);
    times.push_back(run.summary.total_time_s);
  }
  std::sort(times.begin(), times.end());
  run.min_s = times.front();
  run.median_s = times[times.size() / 2];
  run.max_s = times.back();
  return run;
}

// Time to reach and certify the SE-Sync optimum: the Newton solver next to
// the same pipeline with Ceres's Gauss-Newton LM (the reference, same run,
// same chordal start, same certificate, no staircase). Times: median of
// `repeats` (min-max).
void SolveSeSyncCertified(const std::string& dir, const Dataset& d, int repeats) {
  const PoseGraph original = rover::mapping::ReadG2oFile(dir + "/" + d.file);
  const CertifiedRun nt = RunSeSync(original, true, repeats);
  const CertifiedRun gn = RunSeSync(original, false, repeats);
  const PoseGraphSolverSummary& s = nt.summary;
  const rover::mapping::SeSyncCertificate& c = *s.certificate;
  const rover::mapping::SeSyncCertificate& cg = *gn.summary.certificate;
  char published[64] = "          -";
  if (d.published_F > 0.0) {
    std::snprintf(published, sizeof published, "%.3e (%.0e)", d.published_F,
                  std::abs(s.F - d.published_F) / d.published_F);
  }
  std::printf(
      "%-19s %5zu %6zu | F %.9e  F* %s | %-13s lmin %+.1e bound %+.1e | Newton %2d it  init %.3f "
      "cert %.3f total %.3f s (%.3f-%.3f) | Ceres GN %2d it %.3f s (%.3f-%.3f) %-13s "
      "lmin %+.1e F %.9e | x%.2f\n",
      d.file, original.vertices.size(), original.edges.size(), s.F, published,
      c.certified ? "certified" : "NOT certified", c.lambda_min, c.suboptimality_bound,
      s.iterations, s.init_time_s, c.time_s, nt.median_s, nt.min_s, nt.max_s, gn.summary.iterations,
      gn.median_s, gn.min_s, gn.max_s, cg.certified ? "certified" : "NOT certified", cg.lambda_min,
      gn.summary.F, gn.median_s / nt.median_s);
  std::fflush(stdout);
}

void Solve(const std::string& dir, const Dataset& d) {
  const PoseGraph original = rover::mapping::ReadG2oFile(dir + "/" + d.file);
  for (const Objective objective : {Objective::kSeSync, Objective::kChi2}) {
    // Reference in the same run: the same solve with Ceres's default
    // trust-region radius (1e4), otherwise identical.
    PoseGraph r = original;
    PoseGraphSolverOptions ro;
    ro.objective = objective;
    ro.initial_trust_region_radius = 1e4;
    ro.newton = false;  // This table is about Ceres's trust-region radius.
    ro.certify = false;
    const PoseGraphSolverSummary ref = rover::mapping::SolvePoseGraph(r, ro);
    PoseGraph g = original;
    PoseGraphSolverOptions o;
    o.objective = objective;
    o.newton = false;
    o.certify = false;
    const PoseGraphSolverSummary s = rover::mapping::SolvePoseGraph(g, o);
    const bool sesync = objective == Objective::kSeSync;
    std::printf(
        "%-20s %-7s iters %3d  init %6.3f s  total %6.3f s  (radius 1e4: %2d it %6.3f s, x%.2f)  "
        "(GTSAM PDL %5.3f s)  F %.6e",
        d.file, sesync ? "sesync" : "chi2", s.iterations, s.init_time_s, s.total_time_s,
        ref.iterations, ref.total_time_s, ref.total_time_s / s.total_time_s, d.gtsam_s, s.F);
    if (sesync) {
      std::printf("  published %.3e  rel %.1e", d.published_F,
                  std::abs(s.F - d.published_F) / d.published_F);
    } else {
      std::printf("  chi2 %.6e", s.chi2);
    }
    std::printf("\n");
  }
}

void Outliers(const std::string& dir, const char* file, double fraction, bool with_cauchy) {
  const PoseGraph clean = rover::mapping::ReadG2oFile(dir + "/" + file);
  PoseGraphSolverOptions o;
  o.objective = Objective::kSeSync;
  PoseGraph reference = clean;
  const double F0 = rover::mapping::SolvePoseGraph(reference, o).F;
  for (const OutlierHandling handling : {OutlierHandling::kCauchy, OutlierHandling::kGnc}) {
    if (handling == OutlierHandling::kCauchy && !with_cauchy) continue;
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

// Helmert blocking vs the full Ceres solve from the same chordal start
// (chi2 objective). Memory: bytes of factor values + indices (see
// HelmertBlockSummary), not process RSS.
void Helmert(const std::string& dir, const char* file, int block_size,
             rover::mapping::HelmertPartition partition) {
  PoseGraph start = rover::mapping::ReadG2oFile(dir + "/" + file);
  rover::mapping::ChordalInitialisation(start);
  start.vertices_implied = false;
  PoseGraph full = start;
  PoseGraph blocked = start;
  PoseGraphSolverOptions o;
  o.initialisation = rover::mapping::Initialisation::kFile;
  o.function_tolerance = 1e-12;
  o.gradient_tolerance = 1e-12;
  o.parameter_tolerance = 1e-12;
  const PoseGraphSolverSummary f = rover::mapping::SolvePoseGraph(full, o);
  const std::size_t full_bytes = rover::mapping::FullNormalFactorBytes(start, Objective::kChi2);
  rover::mapping::HelmertBlockOptions h;
  h.block_size = block_size;
  h.partition = partition;
  h.function_tolerance = 1e-12;
  const rover::mapping::HelmertBlockSummary s =
      rover::mapping::HelmertBlockSolver(h).Solve(blocked);
  double max_dt = 0.0;
  for (size_t v = 0; v < full.vertices.size(); ++v) {
    max_dt = std::max(
        max_dt,
        (full.vertices[v].pose.translation() - blocked.vertices[v].pose.translation()).norm());
  }
  std::printf(
      "%-20s %-10s blocks of <= %4d: %3d blocks, %5d separator / %5d interior poses, %3d LM steps\n"
      "    full Ceres %.3f s cost %.9e | Helmert %.3f s (eliminate %.3f, separator %.3f, back "
      "%.3f) "
      "cost %.9e (rel %.1e), max |dt| %.1e\n"
      "    memory: full sparse factor %.2f MB | Helmert largest block %.2f MB, all blocks %.2f MB, "
      "separator factor %.2f MB\n",
      file, partition == rover::mapping::HelmertPartition::kSpatial ? "spatial" : "contiguous",
      block_size, s.blocks, s.separator_vertices, s.interior_vertices, s.iterations, f.solve_time_s,
      f.final_cost, s.time_s, s.eliminate_time_s, s.separator_time_s, s.back_time_s, s.final_cost,
      std::abs(s.final_cost - f.final_cost) / f.final_cost, max_dt,
      static_cast<double>(full_bytes) / 1e6, static_cast<double>(s.largest_block_bytes) / 1e6,
      static_cast<double>(s.all_blocks_bytes) / 1e6,
      static_cast<double>(s.separator_factor_bytes) / 1e6);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  std::string dir;
  if (const char* env = std::getenv("ROVER_SHARED_DIR")) dir = std::string(env) + "/data/posegraph";
  if (dir.empty()) dir = ROVER_GRAPH_BENCH_DATA;
  bool outliers = false;
  bool helmert = false;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--data") == 0 && i + 1 < argc) {
      dir = argv[++i];
    } else if (std::strcmp(argv[i], "--outliers") == 0) {
      outliers = true;
    } else if (std::strcmp(argv[i], "--helmert") == 0) {
      helmert = true;
    } else if (std::strcmp(argv[i], "--outlier-case") == 0 && i + 2 < argc) {
      const std::string file = argv[i + 1];
      const double fraction = std::atof(argv[i + 2]);
      i += 2;
      if (dir.empty()) dir = ROVER_GRAPH_BENCH_DATA;
      Outliers(dir, file.c_str(), fraction, false);
      return 0;
    } else {
      std::fprintf(stderr,
                   "usage: bench_graph [--data DIR] [--outliers] [--helmert] [--outlier-case FILE "
                   "FRACTION]\n");
      return 2;
    }
  }
  try {
    std::printf(
        "== SE-Sync objective: time to reach and certify the optimum (chordal init, exact-Hessian "
        "Newton, certificate) vs the same with Ceres's Gauss-Newton LM; median of 3 (min-max)\n");
    for (const Dataset& d : kAllDatasets) SolveSeSyncCertified(dir, d, 3);
    std::printf("\n== Pose graph: time to converge (chordal init + LM, SuiteSparse, 2 threads)\n");
    for (const Dataset& d : kDatasets) Solve(dir, d);
    if (helmert) {
      std::printf("\n== Helmert blocking vs full solve (chi2, 2 threads)\n");
      using rover::mapping::HelmertPartition;
      const char* which = std::getenv("ROVER_HELMERT_ONLY");  // Optional file filter.
      for (const char* file : {"intel.g2o", "parking-garage.g2o", "sphere2500.g2o"}) {
        if (which != nullptr && std::strcmp(which, file) != 0) continue;
        for (const int size : {100, 250}) {
          for (const HelmertPartition p :
               {HelmertPartition::kSpatial, HelmertPartition::kContiguous}) {
            Helmert(dir, file, size, p);
          }
        }
      }
    }
    if (outliers) {
      std::printf("\n== Pose graph: random false loop closures (seeded)\n");
      for (const char* file : {"manhattan.g2o", "sphere2500.g2o"}) {
        for (const double fraction : {0.1, 0.3}) Outliers(dir, file, fraction, true);
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_graph: %s\n", e.what());
    return 1;
  }
  return 0;
}
