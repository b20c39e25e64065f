#ifndef ROVER_MAPPING_GRAPH_OUTLIER_INJECTION_H_
#define ROVER_MAPPING_GRAPH_OUTLIER_INJECTION_H_

// Seeded random false loop closures, for robustness tests and benchmarks.

#include <cstdint>

#include "mapping/graph/pose_graph.h"

namespace rover::mapping {

/// Appends round(fraction * graph.edges.size()) false loop closures between
/// random non-consecutive vertex pairs. Each has a random measurement
/// (uniform rotation, or yaw in 2D; translation uniform in a box of the
/// graph's extent) and the information matrix of a randomly chosen existing
/// loop closure (or edge), so it is as confident as a real one. Returns the
/// number appended; the new edges are the last ones of graph.edges.
int InjectFalseLoopClosures(PoseGraph& graph, double fraction, uint32_t seed);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_GRAPH_OUTLIER_INJECTION_H_
