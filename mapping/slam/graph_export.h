#ifndef ROVER_MAPPING_SLAM_GRAPH_EXPORT_H_
#define ROVER_MAPPING_SLAM_GRAPH_EXPORT_H_

// The rover graph as a plain g2o pose graph (VERTEX_SE3:QUAT, EDGE_SE3:QUAT),
// so any pose-graph tool can inspect or re-solve a mission's graph. Vertex
// ids are 0, 1, ... with the anchored (prior) variable first: g2o tools fix
// the first vertex, which stands for the prior. Priors are not edges.

#include <map>
#include <vector>

#include "mapping/graph/graph_key.h"
#include "mapping/graph/pose_graph.h"
#include "mapping/graph/rover_graph.h"
#include "mapping/slam/graph_factor_record.h"

namespace rover::mapping {

struct ExportedGraph {
  PoseGraph graph;
  /// The rover-graph key of each g2o vertex id.
  std::map<int64_t, GraphKey> key_of_id;
  /// Factors not exported (priors, or variables without an estimate).
  std::size_t skipped = 0;
};

/// Vertices at `solved`'s estimates, one edge per binary factor of
/// `factors` with the information RoverGraph uses for it (frame switches
/// with the stiff roll/pitch prior of `options`).
ExportedGraph ExportToG2o(const RoverGraph& solved, const std::vector<GraphFactorRecord>& factors,
                          const RoverGraphOptions& options);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_SLAM_GRAPH_EXPORT_H_
