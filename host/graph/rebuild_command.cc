// `rover-graph rebuild`: the rover graph of a mission from mapd's logs,
// re-optimised offline and written as g2o.

#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <ostream>

#include "host/graph/commands.h"
#include "mapping/graph/g2o_writer.h"
#include "mapping/graph/rover_graph.h"
#include "mapping/slam/graph_export.h"
#include "mapping/slam/graph_log.h"

namespace rover::host {
namespace {

// Largest position and rotation difference between the offline solution and
// the origins mapd published last (its online estimate).
void CompareWithOnline(const mapping::RoverGraph& graph,
                       const log::rover_msgs::SubmapOrigins& online, std::ostream& out) {
  double max_dp_m = 0.0;
  double max_dtheta_deg = 0.0;
  std::size_t compared = 0;
  for (const log::rover_msgs::SubmapOrigin& o : online.origins) {
    Eigen::Isometry3d offline;
    try {
      offline = graph.Origin(o.robot, o.submap);
    } catch (const mapping::GraphError&) {
      continue;
    }
    const Eigen::Isometry3d T = mapping::FromPoseMsg(o.pose);
    max_dp_m = std::max(max_dp_m, (offline.translation() - T.translation()).norm());
    const Eigen::AngleAxisd d(offline.linear().transpose() * T.linear());
    max_dtheta_deg = std::max(max_dtheta_deg, std::abs(d.angle()) * 180.0 / 3.14159265358979323846);
    ++compared;
  }
  out << "online origins (mapd's last update " << online.update << "): " << compared
      << " compared, largest difference " << max_dp_m << " m, " << max_dtheta_deg << " deg\n";
}

}  // namespace

int RunRebuild(const RebuildCommandOptions& options, std::ostream& out, std::ostream& err) {
  const char* const kTool = "rover-graph rebuild: ";
  if (options.mapd_logs.empty()) {
    err << kTool << "no mapd log given\n";
    return 1;
  }
  mapping::GraphLogContents read;
  try {
    read = mapping::ReadGraphLogs(options.mapd_logs);
  } catch (const std::exception& e) {
    err << kTool << e.what() << "\n";
    return 1;
  }
  for (const std::string& p : read.problems) err << kTool << p << "\n";
  if (read.factors.empty()) {
    err << kTool << "no graph factors (topic " << mapping::kGraphFactorTopic << ") in the logs\n";
    return 1;
  }
  mapping::RoverGraphOptions graph_options;
  graph_options.incremental = false;
  graph_options.compute_origin_covariances = false;
  mapping::RoverGraph graph(graph_options);
  std::map<mapping::FactorKind, std::size_t> count;
  std::size_t refused = 0;
  for (const mapping::GraphFactorRecord& f : read.factors) {
    try {
      mapping::AddToGraph(f, &graph);
      ++count[f.kind];
    } catch (const mapping::GraphError& e) {
      err << kTool << "left out: " << e.what() << "\n";
      ++refused;
    }
  }
  out << "factors: " << read.factors.size() << " read (" << read.duplicates
      << " repeated in a later log), " << refused << " left out;";
  for (const auto& [kind, n] : count) out << " " << mapping::ToString(kind) << " " << n;
  out << "\n";
  mapping::RoverGraphSummary summary;
  try {
    summary = graph.Optimize();
  } catch (const mapping::GraphError& e) {
    err << kTool << e.what() << "\n";
    return 1;
  }
  out << "solved: " << summary.variables << " variables, " << summary.iterations
      << " iterations, cost " << summary.initial_cost << " -> " << summary.final_cost << " in "
      << summary.solve_time_s << " s" << (summary.converged ? "" : " (not converged)") << "\n";
  if (!summary.unanchored.empty()) {
    out << "unanchored (left out): " << summary.unanchored.size() << " variable(s), first "
        << summary.unanchored.front().ToString() << "\n";
  }
  if (read.last_origins) CompareWithOnline(graph, *read.last_origins, out);
  const mapping::ExportedGraph exported = mapping::ExportToG2o(graph, read.factors, graph_options);
  try {
    mapping::WriteG2oFile(exported.graph, options.output);
  } catch (const std::exception& e) {
    err << kTool << e.what() << "\n";
    return 2;
  }
  if (!options.keys_output.empty()) {
    std::ofstream keys(options.keys_output);
    keys << "g2o_id,key\n";
    for (const auto& [id, key] : exported.key_of_id) keys << id << "," << key.ToString() << "\n";
    if (!keys) {
      err << kTool << "cannot write " << options.keys_output << "\n";
      return 2;
    }
  }
  out << "wrote " << options.output << ": " << exported.graph.vertices.size() << " vertices, "
      << exported.graph.edges.size() << " edges (vertex 0 = " << exported.key_of_id.at(0).ToString()
      << ", the anchor)\n";
  out << "RESULT factors=" << read.factors.size()
      << " loop_closures=" << count[mapping::FactorKind::kSubmapMatch]
      << " variables=" << summary.variables << " final_cost=" << summary.final_cost
      << " time_s=" << summary.solve_time_s << "\n";
  return 0;
}

}  // namespace rover::host
