#ifndef ROVER_MAPPING_GRAPH_CHOLMOD_LLT_H_
#define ROVER_MAPPING_GRAPH_CHOLMOD_LLT_H_

// CHOLMOD's sparse Cholesky factorisation L L^T (SuiteSparse, through Eigen),
// supernodal or simplicial as CHOLMOD's analysis prefers (simplicial where
// the factor has little fill, e.g. 2D pose graphs, where the supernodal
// kernels' overhead dominates), and always L L^T rather than L D L^T, so that
// factorising a matrix that is not positive definite fails: info() is then
// Eigen::NumericalIssue. The SE-Sync certificate (a definiteness test) and the
// Newton solver (an indefinite Hessian raises the damping) rely on that.

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCore>

namespace rover::mapping {

class CholmodLlt : public Eigen::CholmodDecomposition<Eigen::SparseMatrix<double>, Eigen::Lower> {
 public:
  CholmodLlt() {
    setMode(Eigen::CholmodAuto);
    cholmod().final_ll = 1;  // Simplicial L L^T too: an indefinite matrix fails.
    cholmod().print = 0;     // A failed factorisation is an answer, not a warning.
  }
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_GRAPH_CHOLMOD_LLT_H_
