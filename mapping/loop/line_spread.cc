#include "mapping/loop/line_spread.h"

#include <algorithm>
#include <random>

namespace rover::mapping {
namespace {

// Points within `distance` (xy) of the line through a and b.
int OnLine(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector2f& a,
           const Eigen::Vector2f& b, float distance) {
  const Eigen::Vector2f d = b - a;
  const float length = d.norm();
  int count = 0;
  if (length < 1e-4f) {
    for (const Eigen::Vector3f& p : points) count += (p.head<2>() - a).norm() <= distance;
    return count;
  }
  const Eigen::Vector2f normal(-d.y() / length, d.x() / length);
  for (const Eigen::Vector3f& p : points) {
    count += std::abs(normal.dot(p.head<2>() - a)) <= distance;
  }
  return count;
}

}  // namespace

int CountOffLine(const std::vector<Eigen::Vector3f>& points, double off_line_distance_m,
                 int max_samples, uint64_t seed) {
  const std::size_t n = points.size();
  if (n < 2) return 0;
  const auto distance = static_cast<float>(off_line_distance_m);
  int best_on = 0;
  const std::size_t pairs = n * (n - 1) / 2;
  if (pairs <= static_cast<std::size_t>(max_samples)) {
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = i + 1; j < n; ++j) {
        best_on =
            std::max(best_on, OnLine(points, points[i].head<2>(), points[j].head<2>(), distance));
      }
    }
  } else {
    std::mt19937_64 rng(seed);
    std::uniform_int_distribution<std::size_t> pick(0, n - 1);
    for (int s = 0; s < max_samples; ++s) {
      const std::size_t i = pick(rng);
      std::size_t j = pick(rng);
      if (j == i) j = (i + 1) % n;
      best_on =
          std::max(best_on, OnLine(points, points[i].head<2>(), points[j].head<2>(), distance));
    }
  }
  return static_cast<int>(n) - best_on;
}

}  // namespace rover::mapping
