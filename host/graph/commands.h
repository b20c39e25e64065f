#ifndef ROVER_HOST_GRAPH_COMMANDS_H_
#define ROVER_HOST_GRAPH_COMMANDS_H_

// The subcommands of `rover-graph`, as functions writing to streams so tests
// can call them directly. Each returns the process exit status: 0 success,
// 1 invalid input (the message names the file and line or the problem),
// 2 an output file could not be written.

#include <ostream>
#include <string>
#include <vector>

#include "mapping/graph/pose_graph_solver.h"

namespace rover::host {

struct SolveCommandOptions {
  std::string input;
  std::string output;
  mapping::PoseGraphSolverOptions solver;
  /// Print one line per Ceres iteration.
  bool progress = true;
};

/// `rover-graph solve IN.g2o OUT.g2o`: initialise, optimise, write OUT, print
/// iterations, times, final cost, chi2 and the SE-Sync objective F, what the
/// objective ignored of the information matrices ("ignored: ..."), and for
/// the SE-Sync objective its optimality certificate ("certificate: certified
/// (lambda_min ...)" or "not certified (lambda_min ...)", the suboptimality
/// bound), ending with one machine-readable line
///   RESULT dataset=... objective=... iterations=... time_s=... final_cost=... F=... chi2=...
///   converged=... rejected=... [certified=yes|no lambda_min=... suboptimality_bound=...]
int RunSolve(const SolveCommandOptions& options, std::ostream& out, std::ostream& err);

struct RebuildCommandOptions {
  /// mapd's logs of one mission, oldest first (a restarted mapd leaves several).
  std::vector<std::string> mapd_logs;
  std::string output;       ///< the g2o file to write
  std::string keys_output;  ///< optional CSV: g2o vertex id -> rover-graph key
};

/// `rover-graph rebuild MAPD_LOG... --out OUT.g2o`: reads every factor mapd
/// logged (damage and malformed factors reported, the rest kept), rebuilds
/// the rover graph, optimises it from scratch, compares it with mapd's last
/// online origins and writes it as g2o (vertex 0 is the anchor). Ends with
///   RESULT factors=... loop_closures=... variables=... final_cost=... time_s=...
int RunRebuild(const RebuildCommandOptions& options, std::ostream& out, std::ostream& err);

/// `rover-graph info IN.g2o`: dimension, vertex and edge counts, loop
/// closures, connected components, F and chi2 of the file's initial guess.
int RunInfo(const std::string& path, std::ostream& out, std::ostream& err);

}  // namespace rover::host

#endif  // ROVER_HOST_GRAPH_COMMANDS_H_
