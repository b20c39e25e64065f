#include "core/stats/chi_square.h"

#include <charconv>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace rover::stats {
namespace {

// Shortest text that reads back as `value`, for error messages.
std::string FormatDouble(double value) {
  char text[32];
  const auto [end, ec] = std::to_chars(text, text + sizeof(text), value);
  return ec == std::errc() ? std::string(text, end) : std::string("?");
}

constexpr double kEpsilon = 1e-16;
constexpr int kMaxIterations = 1000;

// log(x^a e^-x / Gamma(a)), the common prefactor of both expansions.
double LogPrefactor(double a, double x) { return a * std::log(x) - x - std::lgamma(a); }

// P(a, x) by its power series, for x < a + 1:
//   P = x^a e^-x / Gamma(a + 1) * sum_n x^n / ((a + 1) ... (a + n)).
double GammaPSeries(double a, double x) {
  double term = 1.0 / a;
  double sum = term;
  for (int n = 1; n < kMaxIterations; ++n) {
    term *= x / (a + n);
    sum += term;
    if (std::abs(term) < std::abs(sum) * kEpsilon) break;
  }
  return sum * std::exp(LogPrefactor(a, x));
}

// Q(a, x) = 1 - P(a, x) by its continued fraction (modified Lentz), for x >= a + 1.
double GammaQContinuedFraction(double a, double x) {
  constexpr double kTiny = 1e-300;
  double b = x + 1.0 - a;
  double c = 1.0 / kTiny;
  double d = 1.0 / b;
  double h = d;
  for (int i = 1; i < kMaxIterations; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < kEpsilon) break;
  }
  return std::exp(LogPrefactor(a, x)) * h;
}

// Density of the chi-square distribution.
double Chi2Pdf(double dof, double x) {
  if (x <= 0.0) return 0.0;
  const double k = 0.5 * dof;
  return std::exp((k - 1.0) * std::log(x) - 0.5 * x - k * std::log(2.0) - std::lgamma(k));
}

}  // namespace

double RegularizedGammaP(double a, double x) {
  if (!(a > 0.0))
    throw std::invalid_argument("RegularizedGammaP: expected a > 0, found " + FormatDouble(a));
  if (!(x >= 0.0))
    throw std::invalid_argument("RegularizedGammaP: expected x >= 0, found " + FormatDouble(x));
  if (x == 0.0) return 0.0;
  if (std::isinf(x)) return 1.0;
  if (x < a + 1.0) return GammaPSeries(a, x);
  return 1.0 - GammaQContinuedFraction(a, x);
}

double Chi2Cdf(double dof, double x) {
  if (!(dof > 0.0))
    throw std::invalid_argument("Chi2Cdf: expected dof > 0, found " + FormatDouble(dof));
  if (x <= 0.0) return 0.0;
  return RegularizedGammaP(0.5 * dof, 0.5 * x);
}

double Chi2Quantile(double dof, double p) {
  if (!(dof > 0.0))
    throw std::invalid_argument("Chi2Quantile: expected dof > 0, found " + FormatDouble(dof));
  if (!(p >= 0.0 && p <= 1.0)) {
    throw std::invalid_argument("Chi2Quantile: expected p in [0, 1], found " + FormatDouble(p));
  }
  if (p == 0.0) return 0.0;
  if (p == 1.0) return std::numeric_limits<double>::infinity();

  // Bracket the root: Chi2Cdf(lo) < p <= Chi2Cdf(hi).
  double lo = 0.0;
  double hi = std::max(1.0, dof);
  while (Chi2Cdf(dof, hi) < p) {
    lo = hi;
    hi *= 2.0;
  }
  // Newton steps, falling back to bisection whenever a step leaves the bracket.
  double x = 0.5 * (lo + hi);
  for (int i = 0; i < kMaxIterations; ++i) {
    const double f = Chi2Cdf(dof, x) - p;
    if (f == 0.0) return x;
    if (f < 0.0) {
      lo = x;
    } else {
      hi = x;
    }
    if (hi - lo <= 1e-14 * hi) break;
    const double slope = Chi2Pdf(dof, x);
    double next = slope > 0.0 ? x - f / slope : lo;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - x) <= 1e-15 * x) {
      x = next;
      break;
    }
    x = next;
  }
  return x;
}

ChiSquareInterval AverageNeesBounds(int dof, int runs, double confidence) {
  if (dof <= 0)
    throw std::invalid_argument("AverageNeesBounds: expected dof > 0, found " +
                                std::to_string(dof));
  if (runs <= 0) {
    throw std::invalid_argument("AverageNeesBounds: expected runs > 0, found " +
                                std::to_string(runs));
  }
  if (!(confidence > 0.0 && confidence < 1.0)) {
    throw std::invalid_argument("AverageNeesBounds: expected a confidence in (0, 1), found " +
                                FormatDouble(confidence));
  }
  const double total_dof = static_cast<double>(dof) * static_cast<double>(runs);
  const double n = static_cast<double>(runs);
  return {Chi2Quantile(total_dof, 0.5 * (1.0 - confidence)) / n,
          Chi2Quantile(total_dof, 0.5 * (1.0 + confidence)) / n};
}

}  // namespace rover::stats
