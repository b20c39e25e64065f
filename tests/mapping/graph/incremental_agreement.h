#ifndef ROVER_TESTS_MAPPING_GRAPH_INCREMENTAL_AGREEMENT_H_
#define ROVER_TESTS_MAPPING_GRAPH_INCREMENTAL_AGREEMENT_H_

// Runs a synthetic submap sequence through RoverGraph twice, with the
// incremental solver and with full Ceres solves, and checks after every
// update that all origins agree within the stated tolerance.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>

#include "core/geometry/so3.h"
#include "mapping/graph/rover_graph.h"
#include "mapping/graph/synthetic_submap_trajectory.h"

namespace rover::mapping {

// 1 mm and 0.01 deg: the submap matcher's own accuracy is centimetres, so a
// gap this size is far below what pairing, maps or the global pose notice.
inline constexpr double kAgreementTranslationM = 1e-3;
inline constexpr double kAgreementRotationRad = 0.01 * 3.14159265358979 / 180.0;

struct AgreementResult {
  double max_translation_m = 0.0;
  double max_rotation_rad = 0.0;
  int incremental_solves = 0;
  int loop_updates = 0;
  /// Updates left unconverged (one-step updates) and the idle-time steps
  /// (RoverGraph::Refine) taken after them.
  int unconverged_updates = 0;
  int refinement_steps = 0;
};

/// How the incremental side runs: its options, and whether it is refined in
/// idle time (RoverGraph::Refine until converged) before each comparison.
struct AgreementSetup {
  RoverGraphOptions incremental_options{};
  bool refine = false;
  double tolerance_m = kAgreementTranslationM;
  double tolerance_rad = kAgreementRotationRad;
};

inline AgreementResult RunAgainstFullSolves(int submaps, uint32_t seed,
                                            const AgreementSetup& setup = {}) {
  SyntheticSubmapTrajectoryOptions so;
  so.submaps = submaps;
  const SyntheticSubmapTrajectory traj = MakeSyntheticSubmapTrajectory(so, seed);
  RoverGraph incremental(setup.incremental_options);
  RoverGraphOptions full_options;
  full_options.incremental_solve = false;           // Ceres on the whole graph
  full_options.compute_origin_covariances = false;  // not compared here
  RoverGraph full(full_options);
  for (RoverGraph* g : {&incremental, &full}) {
    traj.AddPrior(g);
    g->Optimize();
  }
  AgreementResult out;
  for (size_t i = 0; i < traj.steps.size(); ++i) {
    int loops = 0;
    for (RoverGraph* g : {&incremental, &full}) loops = traj.AddStep(i, g);
    const RoverGraphSummary summary = incremental.Optimize();
    if (setup.refine && incremental.NeedsRefinement()) {
      ++out.unconverged_updates;
      while (incremental.NeedsRefinement()) {
        incremental.Refine();
        ++out.refinement_steps;
      }
    }
    full.Optimize();
    out.loop_updates += loops > 0 ? 1 : 0;
    out.incremental_solves += summary.incremental_solve ? 1 : 0;
    for (int64_t k = 0; k <= traj.steps[i].submap; ++k) {
      const Eigen::Isometry3d a = incremental.Origin(0, k);
      const Eigen::Isometry3d b = full.Origin(0, k);
      const double dt = (a.translation() - b.translation()).norm();
      const double dr = LogSO3(a.linear().transpose() * b.linear()).norm();
      out.max_translation_m = std::max(out.max_translation_m, dt);
      out.max_rotation_rad = std::max(out.max_rotation_rad, dr);
      EXPECT_LT(dt, setup.tolerance_m) << "s0_" << k << " after update " << i;
      EXPECT_LT(dr, setup.tolerance_rad) << "s0_" << k << " after update " << i;
    }
  }
  return out;
}

}  // namespace rover::mapping

#endif  // ROVER_TESTS_MAPPING_GRAPH_INCREMENTAL_AGREEMENT_H_
