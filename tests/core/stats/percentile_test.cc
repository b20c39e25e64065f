#include "core/stats/percentile.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace rover::stats {
namespace {

TEST(PercentileTest, InterpolatesBetweenClosestRanks) {
  const std::vector<double> v = {4.0, 1.0, 3.0, 2.0};  // sorted: 1 2 3 4
  EXPECT_DOUBLE_EQ(Percentile(v, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(Percentile(v, 100.0), 4.0);
  EXPECT_DOUBLE_EQ(Percentile(v, 50.0), 2.5);   // rank 1.5
  EXPECT_DOUBLE_EQ(Percentile(v, 25.0), 1.75);  // rank 0.75
  EXPECT_DOUBLE_EQ(Percentile(v, 99.0), 3.97);  // rank 2.97
}

TEST(PercentileTest, ClampsThePercentAndHandlesSmallInputs) {
  EXPECT_TRUE(std::isnan(Percentile(std::vector<double>{}, 50.0)));
  EXPECT_TRUE(std::isnan(PercentileOfSorted(std::vector<double>{}, 50.0)));
  EXPECT_DOUBLE_EQ(Percentile(std::vector<double>{7.0}, 99.0), 7.0);
  const std::vector<double> v = {1.0, 2.0};
  EXPECT_DOUBLE_EQ(Percentile(v, -5.0), 1.0);
  EXPECT_DOUBLE_EQ(Percentile(v, 250.0), 2.0);
}

TEST(PercentileTest, SelectionAgreesWithSortingOnRandomData) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> value(-1e3, 1e3);
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<double> v(1 + rng() % 200);
    for (double& x : v) x = value(rng);
    std::vector<double> sorted = v;
    std::sort(sorted.begin(), sorted.end());
    for (double p : {0.0, 1.0, 33.3, 50.0, 90.0, 99.0, 99.9, 100.0}) {
      EXPECT_EQ(Percentile(v, p), PercentileOfSorted(sorted, p)) << "n " << v.size() << " p " << p;
    }
  }
}

TEST(PercentileTest, EveryIntegerOfZeroToHundredIsItsOwnPercentile) {
  std::vector<double> v;
  for (int i = 100; i >= 0; --i) v.push_back(i);
  for (int p = 0; p <= 100; ++p) EXPECT_DOUBLE_EQ(Percentile(v, p), p);
}

TEST(PercentileTest, IntegerSamplesUseTheSameDefinition) {
  const std::vector<int64_t> ns = {30, 10, 20};
  EXPECT_DOUBLE_EQ(Percentile(ns, 50.0), 20.0);
  EXPECT_DOUBLE_EQ(Percentile(ns, 75.0), 25.0);
}

}  // namespace
}  // namespace rover::stats
