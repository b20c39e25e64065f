#ifndef ROVER_MAPPING_GRAPH_G2O_WRITER_H_
#define ROVER_MAPPING_GRAPH_G2O_WRITER_H_

// Writer for g2o pose-graph files, the inverse of g2o_reader.h.

#include <ostream>
#include <string>

#include "mapping/graph/pose_graph.h"

namespace rover::mapping {

/// Writes `graph` in g2o format: one VERTEX line per vertex (in graph order),
/// then one EDGE line per edge, 2D records for dimension 2 and
/// SE3:QUAT records otherwise. Every number is written in its shortest
/// round-trip decimal form (up to 17 significant digits), so reading the file
/// back yields the same doubles. Quaternions are written with w >= 0.
void WriteG2o(const PoseGraph& graph, std::ostream& out);

/// As WriteG2o, to the file at `path`. Throws GraphError if it cannot be written.
void WriteG2oFile(const PoseGraph& graph, const std::string& path);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_GRAPH_G2O_WRITER_H_
