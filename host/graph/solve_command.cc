#include <filesystem>
#include <iomanip>
#include <sstream>
#include <string>

#include "host/graph/commands.h"
#include "mapping/graph/g2o_reader.h"
#include "mapping/graph/g2o_writer.h"
#include "mapping/graph/pose_graph_solver.h"

namespace rover::host {
namespace {

// 10 significant digits in scientific notation.
std::string Sci(double value) {
  std::ostringstream os;
  os << std::scientific << std::setprecision(9) << value;
  return os.str();
}

std::string Fixed(double value, int decimals) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(decimals) << value;
  return os.str();
}

}  // namespace

int RunSolve(const SolveCommandOptions& options, std::ostream& out, std::ostream& err) {
  mapping::PoseGraph graph;
  try {
    graph = mapping::ReadG2oFile(options.input);
  } catch (const mapping::GraphError& e) {
    err << "rover-graph: " << e.what() << '\n';
    return 1;
  }
  mapping::PoseGraphSolverOptions solver = options.solver;
  if (options.progress) {
    solver.progress = [&out](int iteration, double cost, double seconds) {
      out << "  iter " << iteration << "  cost " << Sci(cost) << "  t " << Fixed(seconds, 3)
          << " s\n";
    };
  }
  const bool sesync = solver.objective == mapping::Objective::kSeSync;
  out << "rover-graph: " << options.input << ": " << graph.dimension << "D, "
      << graph.vertices.size() << " vertices, " << graph.edges.size() << " edges; objective "
      << (sesync ? "sesync" : "chi2") << '\n';
  mapping::PoseGraphSolverSummary s;
  try {
    s = mapping::SolvePoseGraph(graph, solver);
  } catch (const mapping::GraphError& e) {
    err << "rover-graph: " << e.what() << '\n';
    return 1;
  }
  try {
    mapping::WriteG2oFile(graph, options.output);
  } catch (const mapping::GraphError& e) {
    err << "rover-graph: " << e.what() << '\n';
    return 2;
  }
  out << "  " << s.message << '\n';
  out << "  iterations " << s.iterations << ", init " << Fixed(s.init_time_s, 3) << " s, refine "
      << Fixed(s.solve_time_s, 3) << " s, total " << Fixed(s.total_time_s, 3) << " s\n";
  out << "  initial cost " << Sci(s.initial_cost) << ", final cost " << Sci(s.final_cost) << '\n';
  out << "  F (SE-Sync objective) " << Sci(s.F) << ", chi2 " << Sci(s.chi2) << '\n';
  if (!s.information.Describe().empty()) out << "  ignored: " << s.information.Describe() << '\n';
  if (s.certificate) {
    const mapping::SeSyncCertificate& c = *s.certificate;
    out << "  certificate: " << (c.certified ? "certified" : "not certified") << " (lambda_min "
        << Sci(c.lambda_min) << ", tolerance -" << Sci(c.eta) << "), suboptimality bound "
        << Sci(c.suboptimality_bound) << ", dual bound " << Sci(c.dual_bound) << ", gradient norm "
        << Sci(c.gradient_norm) << ", " << c.factorisations << " factorisations, " << c.iterations
        << " eigen iterations, " << Fixed(c.time_s, 3) << " s\n";
    if (s.staircase_rank > 0) {
      out << "  Riemannian staircase: the rank-" << graph.dimension
          << " critical point was not certified; climbed to rank " << s.staircase_rank << " ("
          << s.staircase_iterations << " gradient steps), rounded and refined\n";
    }
  }
  if (solver.outliers != mapping::OutlierHandling::kNone) {
    out << "  loop closures " << s.loop_closures << ", rejected " << s.rejected << '\n';
  }
  out << "RESULT dataset=" << std::filesystem::path(options.input).stem().string()
      << " objective=" << (sesync ? "sesync" : "chi2") << " iterations=" << s.iterations
      << " time_s=" << Fixed(s.total_time_s, 4) << " final_cost=" << Sci(s.final_cost)
      << " F=" << Sci(s.F) << " chi2=" << Sci(s.chi2)
      << " converged=" << (s.converged ? "yes" : "no") << " rejected=" << s.rejected;
  if (s.certificate) {
    out << " certified=" << (s.certificate->certified ? "yes" : "no")
        << " lambda_min=" << Sci(s.certificate->lambda_min)
        << " suboptimality_bound=" << Sci(s.certificate->suboptimality_bound);
  }
  out << '\n';
  return 0;
}

}  // namespace rover::host
