// rover-graph: solve and inspect g2o pose graphs with the rover's Ceres back end.

#include <CLI/CLI.hpp>

#include <iostream>
#include <map>

#include "host/graph/commands.h"

int main(int argc, char** argv) {
  using rover::mapping::Initialisation;
  using rover::mapping::Objective;
  using rover::mapping::OutlierHandling;
  CLI::App app{
      "rover-graph: pose-graph optimisation on Ceres for g2o files (2D VERTEX_SE2/EDGE_SE2 and\n"
      "3D VERTEX_SE3:QUAT/EDGE_SE3:QUAT). `solve` initialises by chordal relaxation, refines\n"
      "with Levenberg-Marquardt and reports the SE-Sync objective F next to its own cost, so\n"
      "results compare with published certified optima. `rebuild` turns a mission's mapd logs\n"
      "into the rover graph, re-optimised, as g2o."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "rover-graph 0.1.0");

  std::string info_path;
  auto* info = app.add_subcommand(
      "info", "Vertex/edge counts, dimension, loop closures, connected components");
  info->add_option("IN", info_path, "pose graph (.g2o)")->required()->check(CLI::ExistingFile);

  rover::host::SolveCommandOptions solve_options;
  std::string objective = "chi2";
  std::string init = "chordal";
  std::string outliers = "none";
  bool quiet = false;
  auto* solve = app.add_subcommand("solve", "Optimise IN and write the solution to OUT");
  solve->add_option("IN", solve_options.input, "pose graph to solve (.g2o)")
      ->required()
      ->check(CLI::ExistingFile);
  solve->add_option("OUT", solve_options.output, "solution to write (.g2o, full precision)")
      ->required();
  solve
      ->add_option("--objective", objective,
                   "chi2: g2o's full-information objective; sesync: SE-Sync's isotropic "
                   "objective F (chordal rotation distance weighted by kappa, translation by tau)")
      ->check(CLI::IsMember({"chi2", "sesync"}))
      ->capture_default_str();
  solve
      ->add_option("--init", init,
                   "chordal: chordal relaxation + linear translations; odometry: compose "
                   "edges along a spanning tree; file: the file's vertices")
      ->check(CLI::IsMember({"chordal", "odometry", "file"}))
      ->capture_default_str();
  solve
      ->add_option("--outliers", outliers,
                   "loop-closure outlier handling: none, cauchy (robust loss) or gnc "
                   "(graduated non-convexity, then least squares on the kept edges)")
      ->check(CLI::IsMember({"none", "cauchy", "gnc"}))
      ->capture_default_str();
  solve->add_option("--cauchy-scale", solve_options.solver.cauchy_scale, "Cauchy loss scale")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  solve
      ->add_option("--gnc-threshold", solve_options.solver.gnc_threshold,
                   "GNC: squared residual above which a loop closure is an outlier")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  std::string sesync_solver = "newton";
  solve
      ->add_option("--sesync-solver", sesync_solver,
                   "sesync objective: newton (exact Hessian, quadratic convergence) or ceres "
                   "(Gauss-Newton LM)")
      ->check(CLI::IsMember({"newton", "ceres"}))
      ->capture_default_str();
  bool no_certificate = false;
  solve->add_flag("--no-certificate", no_certificate,
                  "sesync objective: skip SE-Sync's optimality certificate");
  std::string trust_region = "lm";
  solve->add_option("--trust-region", trust_region, "lm (Levenberg-Marquardt) or dogleg")
      ->check(CLI::IsMember({"lm", "dogleg"}))
      ->capture_default_str();
  solve
      ->add_option("--initial-radius", solve_options.solver.initial_trust_region_radius,
                   "initial trust-region radius")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  solve->add_option("--max-iterations", solve_options.solver.max_iterations, "Ceres iterations")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  solve
      ->add_option("--function-tolerance", solve_options.solver.function_tolerance,
                   "Ceres: stop on a relative cost decrease below this")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  solve
      ->add_option("--gradient-tolerance", solve_options.solver.gradient_tolerance,
                   "Ceres: stop on a gradient max-norm below this")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  solve->add_option("--threads", solve_options.solver.num_threads, "Ceres threads")
      ->check(CLI::Range(1, 256))
      ->capture_default_str();
  solve->add_flag("-q,--quiet", quiet, "no per-iteration progress lines");

  rover::host::RebuildCommandOptions rebuild_options;
  auto* rebuild = app.add_subcommand(
      "rebuild",
      "Rebuild a mission's rover graph from mapd's logs (every factor mapd logged as it added\n"
      "it), optimise it from scratch, compare with mapd's last online origins and write it as\n"
      "g2o (vertex 0 is the anchored first origin)");
  rebuild->add_option("MAPD_LOG", rebuild_options.mapd_logs, "mapd logs (.mcap), oldest first")
      ->required()
      ->check(CLI::ExistingFile);
  rebuild->add_option("--out", rebuild_options.output, "g2o file to write")->required();
  rebuild->add_option("--keys", rebuild_options.keys_output,
                      "also write a CSV mapping g2o vertex ids to graph keys (s0_3, x0_17, l4)");

  CLI11_PARSE(app, argc, argv);

  if (*info) return rover::host::RunInfo(info_path, std::cout, std::cerr);
  if (*rebuild) return rover::host::RunRebuild(rebuild_options, std::cout, std::cerr);
  if (*solve) {
    static const std::map<std::string, Objective> kObjectives = {{"chi2", Objective::kChi2},
                                                                 {"sesync", Objective::kSeSync}};
    static const std::map<std::string, Initialisation> kInits = {
        {"chordal", Initialisation::kChordal},
        {"odometry", Initialisation::kOdometry},
        {"file", Initialisation::kFile}};
    static const std::map<std::string, OutlierHandling> kOutliers = {
        {"none", OutlierHandling::kNone},
        {"cauchy", OutlierHandling::kCauchy},
        {"gnc", OutlierHandling::kGnc}};
    solve_options.solver.objective = kObjectives.at(objective);
    solve_options.solver.initialisation = kInits.at(init);
    solve_options.solver.outliers = kOutliers.at(outliers);
    solve_options.progress = !quiet;
    solve_options.solver.dogleg = trust_region == "dogleg";
    solve_options.solver.newton = sesync_solver == "newton";
    solve_options.solver.certify = !no_certificate;
    return rover::host::RunSolve(solve_options, std::cout, std::cerr);
  }
  return 2;
}
