#ifndef ROVER_MAPPING_GRAPH_GRAPH_CONNECTIVITY_H_
#define ROVER_MAPPING_GRAPH_GRAPH_CONNECTIVITY_H_

// Connected components of a g2o pose graph and the gauge check.

#include <cstdint>
#include <string>
#include <vector>

#include "mapping/graph/pose_graph.h"

namespace rover::mapping {

/// Component label (0, 1, ...) of every vertex of graph.vertices, in order;
/// components are numbered in order of their first vertex.
std::vector<int> ConnectedComponents(const PoseGraph& graph);

/// Throws GraphError naming the problem if the graph has a gauge freedom the
/// solver cannot remove: no vertex at all, or more than one connected
/// component (only the first vertex is anchored). The message lists each
/// unanchored component by its vertex ids (first few) and size. Also throws
/// for NaN/infinite vertex poses or edge measurements ("NaN input").
void CheckGaugeAndFinite(const PoseGraph& graph);

/// "ids 5, 6, 7, ... (12 vertices)": a short description of a vertex set.
std::string DescribeIds(const std::vector<int64_t>& ids);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_GRAPH_GRAPH_CONNECTIVITY_H_
