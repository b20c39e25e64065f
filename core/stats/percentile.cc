#include "core/stats/percentile.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rover::stats {
namespace {

// Fractional rank of the percentile among n sorted values.
double RankOf(std::size_t n, double percent) {
  return std::clamp(percent, 0.0, 100.0) / 100.0 * static_cast<double>(n - 1);
}

}  // namespace

double PercentileOfSorted(std::span<const double> sorted, double percent) {
  if (sorted.empty()) return std::numeric_limits<double>::quiet_NaN();
  const double rank = RankOf(sorted.size(), percent);
  const auto lo = static_cast<std::size_t>(std::floor(rank));
  const std::size_t hi = std::min(lo + 1, sorted.size() - 1);
  const double f = rank - static_cast<double>(lo);
  return sorted[lo] + f * (sorted[hi] - sorted[lo]);
}

double Percentile(std::span<const double> values, double percent) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  // Only the two neighbouring ranks are needed: select them instead of sorting.
  std::vector<double> v(values.begin(), values.end());
  const double rank = RankOf(v.size(), percent);
  const auto lo = static_cast<std::ptrdiff_t>(std::floor(rank));
  std::nth_element(v.begin(), v.begin() + lo, v.end());
  const double low = v[static_cast<std::size_t>(lo)];
  if (static_cast<std::size_t>(lo) + 1 >= v.size()) return low;
  const double high = *std::min_element(v.begin() + lo + 1, v.end());
  return low + (rank - static_cast<double>(lo)) * (high - low);
}

double Percentile(std::span<const int64_t> values, double percent) {
  std::vector<double> v(values.size());
  std::transform(values.begin(), values.end(), v.begin(),
                 [](int64_t x) { return static_cast<double>(x); });
  return Percentile(std::span<const double>(v), percent);
}

}  // namespace rover::stats
