#include "estimator/eskf/update/chi_square_gate.h"

#include "core/stats/chi_square.h"

namespace rover::estimator {

double ChiSquareGate(int dof, double probability) {
  // probability == 1 means "never gate".
  if (probability >= 1.0) return 0.0;
  return rover::stats::Chi2Quantile(static_cast<double>(dof), probability);
}

}  // namespace rover::estimator
