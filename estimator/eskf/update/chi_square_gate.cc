#include "estimator/eskf/update/chi_square_gate.h"

#include <cmath>

namespace rover::estimator {
namespace {

// Regularised lower incomplete gamma P(a, x) by its power series.
double LowerGammaP(double a, double x) {
  if (x <= 0.0) return 0.0;
  double term = 1.0 / a, sum = term;
  for (int n = 1; n < 100000 && term > sum * 1e-16; ++n) {
    term *= x / (a + n);
    sum += term;
  }
  return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

}  // namespace

double ChiSquareGate(int dof, double probability) {
  const double a = 0.5 * dof;
  double lo = 0.0, hi = 10.0 * dof + 100.0;
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    (LowerGammaP(a, 0.5 * mid) < probability ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace rover::estimator
