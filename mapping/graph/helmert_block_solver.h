#ifndef ROVER_MAPPING_GRAPH_HELMERT_BLOCK_SOLVER_H_
#define ROVER_MAPPING_GRAPH_HELMERT_BLOCK_SOLVER_H_

// Helmert blocking (Helmert 1880; the geodetic-mapping survey, Sec. V-A) for
// g2o pose graphs: a Levenberg-Marquardt / Gauss-Newton solver whose linear
// step is computed block by block.
//
// The vertices are partitioned into blocks (contiguous ranges of vertex
// order, or an explicit partition such as one block per submap). A vertex
// with an edge to a vertex of another block is a separator; the others are
// interior. Per iteration, each block (in parallel) builds the normal
// equations of its internal edges,
//
//     [H_II  H_IS] [d_I]   [b_I]
//     [H_SI  H_SS] [d_S] = [b_S],      H = J^T J + lambda D,  b = -J^T r,
//
// and eliminates its interior exactly (sparse Cholesky of H_II):
//
//     S_b = H_SS - H_SI H_II^-1 H_IS,  c_b = b_S - H_SI H_II^-1 b_I.
//
// The reduced (separator) system sum_b S_b + (edges between blocks) is solved
// exactly by sparse Cholesky, and each block back-substitutes
// d_I = H_II^-1 (b_I - H_IS d_S) in parallel. The step is therefore the exact
// LM step of the full problem; only the order of elimination differs.
// The first vertex is held fixed (same gauge as SolvePoseGraph).

#include <cstddef>
#include <vector>

#include "mapping/graph/pose_graph.h"
#include "mapping/graph/pose_graph_solver.h"

namespace rover::mapping {

enum class HelmertPartition {
  kContiguous,  ///< Ranges of block_size vertices in graph.vertices order.
  kSpatial,     ///< Recursive coordinate bisection of the positions at the
                ///< start (split at the median of the widest axis until a
                ///< block has at most block_size vertices): geographic blocks,
                ///< as for NAD 83.
};

struct HelmertBlockOptions {
  Objective objective = Objective::kChi2;
  HelmertPartition partition = HelmertPartition::kContiguous;
  /// Maximum vertices per block, if no explicit partition is given.
  int block_size = 200;
  /// Optional explicit partition: block index per vertex (graph.vertices
  /// order), e.g. the submap of each pose. Overrides block_size if non-empty.
  std::vector<int> block_of_vertex;
  int num_threads = 2;
  int max_iterations = 100;
  /// Stop when the relative cost decrease of an accepted step is below this,
  /// or |step| <= step_tolerance (|x| + step_tolerance) (Ceres's parameter
  /// tolerance).
  double function_tolerance = 1e-14;
  double step_tolerance = 1e-10;
  /// Initial LM damping lambda (H + lambda diag(H)), then Nielsen's update
  /// from the gain ratio (actual / predicted decrease) as in Ceres.
  double initial_lambda = 1e-6;
};

struct HelmertBlockSummary {
  int iterations = 0;          ///< Accepted + rejected LM steps.
  int blocks = 0;              ///< Blocks with at least one free vertex.
  int separator_vertices = 0;  ///< Vertices in the reduced system.
  int interior_vertices = 0;   ///< Vertices eliminated inside their block.
  double initial_cost = 0.0;   ///< 0.5 sum |r|^2 (the Ceres convention).
  double final_cost = 0.0;
  double time_s = 0.0;            ///< Whole solve.
  double eliminate_time_s = 0.0;  ///< Linearise + eliminate (parallel part).
  double separator_time_s = 0.0;  ///< Assemble + factor + solve the reduced system.
  double back_time_s = 0.0;       ///< Back-substitution.
  /// Memory of the linear algebra (bytes of stored values and indices, last
  /// iteration): the largest single block working set (sparse factor of H_II,
  /// dense H_IS, H_II^-1 H_IS and S_b), the sum over blocks, and the sparse
  /// factor of the reduced system.
  std::size_t largest_block_bytes = 0;
  std::size_t all_blocks_bytes = 0;
  std::size_t separator_factor_bytes = 0;
  bool converged = false;
};

class HelmertBlockSolver {
 public:
  explicit HelmertBlockSolver(HelmertBlockOptions options);

  /// Optimises graph.vertices in place (first vertex fixed). Throws GraphError
  /// for gauge/NaN problems (CheckGaugeAndFinite), an information matrix the
  /// objective cannot use (CheckInformation) or a singular system.
  HelmertBlockSummary Solve(PoseGraph& graph) const;

 private:
  HelmertBlockOptions options_;
};

/// Block index per vertex (graph.vertices order) for the given scheme.
std::vector<int> PartitionVertices(const PoseGraph& graph, HelmertPartition partition,
                                   int block_size);

/// Bytes of the sparse Cholesky factor (Eigen SimplicialLLT, AMD ordering) of
/// the full Gauss-Newton normal matrix at the current vertices: the
/// single-factorisation reference for HelmertBlockSummary's memory figures.
std::size_t FullNormalFactorBytes(const PoseGraph& graph, Objective objective);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_GRAPH_HELMERT_BLOCK_SOLVER_H_
