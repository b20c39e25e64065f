#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "core/stats/chi_square.h"

namespace rover::stats {
namespace {

TEST(Chi2QuantileTest, MatchesTableValues) {
  EXPECT_NEAR(Chi2Quantile(3, 0.975), 9.348, 5e-4);
  EXPECT_NEAR(Chi2Quantile(3, 0.025), 0.2158, 5e-5);
  EXPECT_NEAR(Chi2Quantile(75, 0.975), 100.839, 5e-4);
  EXPECT_NEAR(Chi2Quantile(75, 0.025), 52.942, 5e-4);
  EXPECT_NEAR(Chi2Quantile(1, 0.95), 3.841459, 1e-6);
  EXPECT_NEAR(Chi2Quantile(6, 0.99), 16.811894, 1e-6);
  EXPECT_NEAR(Chi2Quantile(1, 0.5), 0.454936, 1e-6);
}

TEST(Chi2QuantileTest, TwoDofHasAClosedForm) {
  // Chi-square with 2 dof is exponential: quantile = -2 ln(1 - p).
  for (const double p : {1e-9, 1e-3, 0.1, 0.5, 0.9, 0.999, 1.0 - 1e-9}) {
    EXPECT_NEAR(Chi2Quantile(2, p), -2.0 * std::log1p(-p), 1e-9 * (1.0 - 2.0 * std::log1p(-p)))
        << p;
  }
}

TEST(Chi2QuantileTest, InvertsTheCdf) {
  for (const double dof : {0.5, 1.0, 3.0, 6.0, 15.0, 75.0, 300.0, 3000.0}) {
    for (const double p : {1e-6, 0.025, 0.5, 0.975, 1.0 - 1e-7}) {
      const double x = Chi2Quantile(dof, p);
      EXPECT_NEAR(Chi2Cdf(dof, x), p, 1e-12) << "dof " << dof << " p " << p;
    }
  }
  EXPECT_EQ(Chi2Quantile(3, 0.0), 0.0);
  EXPECT_TRUE(std::isinf(Chi2Quantile(3, 1.0)));
  EXPECT_THROW(Chi2Quantile(0, 0.5), std::invalid_argument);
  EXPECT_THROW(Chi2Quantile(3, 1.5), std::invalid_argument);
}

TEST(RegularizedGammaPTest, KnownValues) {
  // P(1, x) = 1 - e^-x; P(0.5, x) = erf(sqrt(x)).
  for (const double x : {0.01, 0.5, 1.0, 2.0, 10.0, 40.0}) {
    EXPECT_NEAR(RegularizedGammaP(1.0, x), -std::expm1(-x), 1e-14) << x;
    EXPECT_NEAR(RegularizedGammaP(0.5, x), std::erf(std::sqrt(x)), 1e-14) << x;
  }
  EXPECT_EQ(RegularizedGammaP(2.0, 0.0), 0.0);
}

TEST(AverageNeesBoundsTest, MatchesScaledQuantiles) {
  const ChiSquareInterval b = AverageNeesBounds(3, 25);
  EXPECT_NEAR(b.lower, 52.942 / 25.0, 2e-5);
  EXPECT_NEAR(b.upper, 100.839 / 25.0, 2e-5);
  const ChiSquareInterval one = AverageNeesBounds(3, 1, 0.95);
  EXPECT_NEAR(one.lower, 0.2158, 5e-5);
  EXPECT_NEAR(one.upper, 9.348, 5e-4);
  // Narrower with more runs, wider with more confidence.
  EXPECT_LT(AverageNeesBounds(3, 100).upper, b.upper);
  EXPECT_GT(AverageNeesBounds(3, 25, 0.99).upper, b.upper);
  EXPECT_THROW(AverageNeesBounds(3, 0), std::invalid_argument);
  EXPECT_THROW(AverageNeesBounds(3, 10, 1.0), std::invalid_argument);
}

}  // namespace
}  // namespace rover::stats
