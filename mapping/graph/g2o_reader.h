#ifndef ROVER_MAPPING_GRAPH_G2O_READER_H_
#define ROVER_MAPPING_GRAPH_G2O_READER_H_

// Reader for g2o pose-graph files: VERTEX_SE3:QUAT / EDGE_SE3:QUAT (3D) and
// VERTEX_SE2 / EDGE_SE2 (2D). Blank lines and lines starting with '#' are
// skipped; FIX lines are accepted and ignored (the solver fixes the first
// vertex). Files without any VERTEX line (e.g. CSAIL, manhattan) are valid:
// their vertices are implied by the edges.

#include <istream>
#include <string>

#include "mapping/graph/pose_graph.h"

namespace rover::mapping {

/// Reads the g2o file at `path`. Throws GraphError "path:line: expected ...,
/// found ..." for a malformed line (unknown tag, missing or non-numeric
/// field, NaN/infinite value, zero quaternion, 2D and 3D records mixed), an
/// information matrix whose translation or rotation block is not positive
/// definite, a duplicate vertex, a
/// self-loop edge, or an edge referencing a vertex that no VERTEX line
/// defines (when the file has VERTEX lines). Quaternions are normalised. A
/// matrix that is indefinite only as a whole (through its rotation-translation
/// off-diagonal block) is read: the SE-Sync objective uses the two diagonal
/// blocks only; CheckInformation refuses it for chi2.
PoseGraph ReadG2oFile(const std::string& path);

/// As ReadG2oFile, from a stream; `source_name` stands for the file name in
/// error messages.
PoseGraph ReadG2o(std::istream& in, const std::string& source_name);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_GRAPH_G2O_READER_H_
