#include "hil/sim/motion/smooth_profiles.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace rover::sim {
namespace {

TEST(SepticStepTest, EndpointsAndDerivatives) {
  EXPECT_EQ(SepticStep::Value(0.0), 0.0);
  EXPECT_DOUBLE_EQ(SepticStep::Value(1.0), 1.0);
  EXPECT_DOUBLE_EQ(SepticStep::Value(0.5), 0.5);
  for (double x : {0.0, 1.0}) {
    EXPECT_EQ(SepticStep::D1(x), 0.0);
    EXPECT_EQ(SepticStep::D2(x), 0.0);
    EXPECT_NEAR(SepticStep::D3(x), 0.0, 1e-12);
  }
  EXPECT_DOUBLE_EQ(SepticStep::Integral(1.0), 0.5);
  const double h = 1e-5;
  for (double x = 0.05; x < 1.0; x += 0.1) {
    EXPECT_NEAR((SepticStep::Value(x + h) - SepticStep::Value(x - h)) / (2 * h), SepticStep::D1(x),
                1e-8);
    EXPECT_NEAR((SepticStep::D1(x + h) - SepticStep::D1(x - h)) / (2 * h), SepticStep::D2(x), 1e-7);
    EXPECT_NEAR((SepticStep::D2(x + h) - SepticStep::D2(x - h)) / (2 * h), SepticStep::D3(x), 1e-6);
    EXPECT_NEAR((SepticStep::Integral(x + h) - SepticStep::Integral(x - h)) / (2 * h),
                SepticStep::Value(x), 1e-9);
  }
  double max_d1 = 0.0, max_d2 = 0.0;
  for (int i = 0; i <= 100000; ++i) {
    max_d1 = std::max(max_d1, std::abs(SepticStep::D1(i * 1e-5)));
    max_d2 = std::max(max_d2, std::abs(SepticStep::D2(i * 1e-5)));
  }
  EXPECT_NEAR(max_d1, SepticStep::kMaxFirstDerivative, 1e-9);
  EXPECT_NEAR(max_d2, SepticStep::kMaxSecondDerivative, 1e-4);
}

TEST(QuinticBSplineTest, ReproducesConstantsAndLines) {
  const QuinticBSpline constant(std::vector<double>(20, 3.5), 0.1);
  const QuinticBSpline line(
      [] {
        std::vector<double> v;
        for (int i = 0; i < 40; ++i) v.push_back(0.3 * i * 0.05 - 1.0);
        return v;
      }(),
      0.05);
  for (double u = -0.5; u < 2.5; u += 0.013) {
    const Jet2 c = constant.Evaluate(u);
    EXPECT_NEAR(c.value, 3.5, 1e-12);
    EXPECT_NEAR(c.d1, 0.0, 1e-9);
    EXPECT_NEAR(c.d2, 0.0, 1e-6);
  }
  // Away from the clamped ends a B-spline reproduces linear functions exactly.
  for (double u = 0.2; u < 1.7; u += 0.0123) {
    const Jet2 l = line.Evaluate(u);
    EXPECT_NEAR(l.value, 0.3 * u - 1.0, 1e-12);
    EXPECT_NEAR(l.d1, 0.3, 1e-9);
    EXPECT_NEAR(l.d2, 0.0, 1e-6);
  }
}

TEST(QuinticBSplineTest, DerivativesMatchAndAreContinuousAcrossKnots) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> d(-1.0, 1.0);
  std::vector<double> samples(50);
  for (double& s : samples) s = d(rng);
  const double spacing = 0.05;
  const QuinticBSpline spline(samples, spacing);
  const double h = 1e-6;
  for (int knot = -3; knot < 55; ++knot) {
    const double u = knot * spacing;
    // Over +-1e-9 the pieces may differ by the derivative times 2e-9, no more
    // (random samples 5 cm apart: |d1| < 1e2, |d2| < 1e4, |d3| < 1e6).
    const Jet2 before = spline.Evaluate(u - 1e-9), after = spline.Evaluate(u + 1e-9);
    EXPECT_NEAR(before.value, after.value, 1e-6) << "knot " << knot;
    EXPECT_NEAR(before.d1, after.d1, 1e-4) << "knot " << knot;
    EXPECT_NEAR(before.d2, after.d2, 1e-2) << "knot " << knot;
    const double mid = u + 0.37 * spacing;
    const Jet2 j = spline.Evaluate(mid);
    EXPECT_NEAR((spline.Evaluate(mid + h).value - spline.Evaluate(mid - h).value) / (2 * h), j.d1,
                1e-6);
    EXPECT_NEAR((spline.Evaluate(mid + h).d1 - spline.Evaluate(mid - h).d1) / (2 * h), j.d2, 1e-3);
  }
  // Far outside the samples the spline is flat at the end samples.
  EXPECT_DOUBLE_EQ(spline.Evaluate(-10.0).value, samples.front());
  EXPECT_DOUBLE_EQ(spline.Evaluate(100.0).value, samples.back());
}

}  // namespace
}  // namespace rover::sim
