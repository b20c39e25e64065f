#ifndef ROVER_ESTIMATOR_ESKF_UPDATE_CHI_SQUARE_GATE_H_
#define ROVER_ESTIMATOR_ESKF_UPDATE_CHI_SQUARE_GATE_H_

namespace rover::estimator {

/// The Mahalanobis gate for a `dof`-dimensional innovation: the chi-square
/// quantile at `probability` (e.g. 0.999). Computed once per updater at
/// construction, never in the real-time path.
double ChiSquareGate(int dof, double probability);

}  // namespace rover::estimator

#endif  // ROVER_ESTIMATOR_ESKF_UPDATE_CHI_SQUARE_GATE_H_
