#ifndef ROVER_CORE_STATS_PERCENTILE_H_
#define ROVER_CORE_STATS_PERCENTILE_H_

// The one percentile of the project: reports, benchmarks and health checks
// all quote the same statistic, so their figures can be compared.
//
// Definition: linear interpolation between the closest ranks of the sorted
// values (Hyndman & Fan type 7, numpy's and Excel's default): the p-th
// percentile of n values is at rank r = p / 100 * (n - 1), between the
// floor(r)-th and ceil(r)-th smallest. p = 0 is the minimum, p = 100 the
// maximum, p = 50 the median.

#include <cstdint>
#include <span>
#include <vector>

namespace rover::stats {

/// The `percent`-th percentile (clamped to [0, 100]) of `values`, which need
/// not be sorted; NaN when `values` is empty. Copies and partially sorts:
/// O(n) per call.
double Percentile(std::span<const double> values, double percent);

/// As Percentile(), for integer samples (nanoseconds, counts).
double Percentile(std::span<const int64_t> values, double percent);

/// The `percent`-th percentile of values already sorted ascending (not
/// checked); NaN when empty. O(1).
double PercentileOfSorted(std::span<const double> sorted, double percent);

}  // namespace rover::stats

#endif  // ROVER_CORE_STATS_PERCENTILE_H_
