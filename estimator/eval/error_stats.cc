#include "estimator/eval/error_stats.h"

#include <algorithm>
#include <cmath>

namespace rover::eval {

ErrorStats ComputeErrorStats(std::vector<double> values) {
  ErrorStats s;
  if (values.empty()) return s;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  const double count = static_cast<double>(n);
  double sum = 0.0, sum_squares = 0.0;
  for (const double v : values) {
    sum += v;
    sum_squares += v * v;
  }
  s.count = n;
  s.mean = sum / count;
  s.rmse = std::sqrt(sum_squares / count);
  double deviation = 0.0;
  for (const double v : values) deviation += (v - s.mean) * (v - s.mean);
  s.std = std::sqrt(deviation / count);
  s.median = n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
  s.min = values.front();
  s.max = values.back();
  return s;
}

}  // namespace rover::eval
