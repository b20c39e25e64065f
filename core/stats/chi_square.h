#ifndef ROVER_CORE_STATS_CHI_SQUARE_H_
#define ROVER_CORE_STATS_CHI_SQUARE_H_

// The chi-square distribution: CDF and quantile for the filter's innovation
// gates, NEES/NIS consistency bounds and the pose graph's robust thresholds.
// Bad arguments throw std::invalid_argument naming the argument and value.

namespace rover::stats {

/// Regularized lower incomplete gamma function P(a, x) = gamma(a, x) / Gamma(a)
/// for a > 0, x >= 0 (series for x < a + 1, continued fraction otherwise),
/// accurate to about 1e-14. Throws std::invalid_argument for a <= 0 or x < 0.
double RegularizedGammaP(double a, double x);

/// CDF of the chi-square distribution with `dof` degrees of freedom at x:
/// P(dof / 2, x / 2). Zero for x <= 0. Throws std::invalid_argument for dof <= 0.
double Chi2Cdf(double dof, double x);

/// Quantile (inverse CDF) of the chi-square distribution: the x with
/// Chi2Cdf(dof, x) == p, e.g. Chi2Quantile(3, 0.975) = 9.348. Solved by
/// safeguarded Newton iteration on a bracket, to a relative accuracy of about
/// 1e-12. p = 0 gives 0 and p = 1 infinity. Throws std::invalid_argument for dof <= 0 or
/// p outside [0, 1].
double Chi2Quantile(double dof, double p);

/// Two-sided interval [lower, upper].
struct ChiSquareInterval {
  double lower = 0.0;
  double upper = 0.0;
};

/// Acceptance interval of the NEES averaged over `runs` independent runs (or
/// samples) of a `dof`-dimensional error with the given two-sided confidence:
///   [Chi2Quantile(dof * runs, (1 - c) / 2) / runs, Chi2Quantile(dof * runs, (1 + c) / 2) / runs].
/// For dof = 3, runs = 25, c = 0.95: [2.118, 4.034]. Throws std::invalid_argument for
/// dof <= 0, runs == 0 or confidence outside (0, 1).
ChiSquareInterval AverageNeesBounds(int dof, int runs, double confidence = 0.95);

}  // namespace rover::stats

#endif  // ROVER_CORE_STATS_CHI_SQUARE_H_
