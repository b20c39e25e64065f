#include <algorithm>

#include "host/graph/commands.h"
#include "mapping/graph/g2o_reader.h"
#include "mapping/graph/graph_connectivity.h"
#include "mapping/graph/se_sync_objective.h"

namespace rover::host {

int RunInfo(const std::string& path, std::ostream& out, std::ostream& err) {
  mapping::PoseGraph graph;
  try {
    graph = mapping::ReadG2oFile(path);
  } catch (const mapping::GraphError& e) {
    err << "rover-graph: " << e.what() << '\n';
    return 1;
  }
  const std::vector<int> label = mapping::ConnectedComponents(graph);
  const int components = label.empty() ? 0 : *std::max_element(label.begin(), label.end()) + 1;
  int loop_closures = 0;
  for (const auto& e : graph.edges) loop_closures += mapping::IsLoopClosure(e) ? 1 : 0;
  out << "file:            " << path << '\n'
      << "dimension:       " << graph.dimension << "D ("
      << (graph.dimension == 2 ? "VERTEX_SE2/EDGE_SE2" : "VERTEX_SE3:QUAT/EDGE_SE3:QUAT") << ")\n"
      << "vertices:        " << graph.vertices.size()
      << (graph.vertices_implied ? " (implied by the edges: no VERTEX lines)" : "") << '\n'
      << "edges:           " << graph.edges.size() << " (" << loop_closures << " loop closures, "
      << graph.edges.size() - static_cast<size_t>(loop_closures) << " odometry)\n"
      << "components:      " << components
      << (components == 1 ? " (connected)" : " (gauge problem: only the first vertex is anchored)")
      << '\n';
  if (!graph.vertices_implied) {
    out << "initial guess:   F " << mapping::SeSyncObjective(graph) << ", chi2 "
        << mapping::Chi2Objective(graph) << '\n';
  }
  return 0;
}

}  // namespace rover::host
