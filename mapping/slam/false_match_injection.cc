#include "mapping/slam/false_match_injection.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>

#include "core/geometry/yaw.h"

namespace rover::mapping {
namespace {

void Check(bool ok, const char* key, const std::string& expected, double found) {
  if (!ok) {
    throw std::invalid_argument(std::string("FalseMatchOptions.") + key + ": expected " + expected +
                                ", found " + std::to_string(found));
  }
}

// The covariance of the graph's first true match, or a typical one.
Matrix6d MatchCovariance(const std::vector<GraphFactorRecord>& factors) {
  for (const GraphFactorRecord& f : factors) {
    if (f.kind == FactorKind::kSubmapMatch) return f.covariance;
  }
  Matrix6d c = Matrix6d::Zero();
  const double yaw = 0.5 * M_PI / 180.0;
  c.diagonal() << 0.0025, 0.0025, 0.0025, 2.5e-5, 2.5e-5, yaw * yaw;
  return c;
}

// Origin pairs near each other by the estimates, not successive.
std::vector<std::pair<int64_t, int64_t>> NearPairs(
    const std::map<int64_t, Eigen::Isometry3d>& T_world_origin, double near_m) {
  std::vector<std::pair<int64_t, int64_t>> pairs;
  for (auto a = T_world_origin.begin(); a != T_world_origin.end(); ++a) {
    for (auto b = std::next(a); b != T_world_origin.end(); ++b) {
      if (b->first - a->first < 2) continue;
      const double d = (a->second.translation() - b->second.translation()).norm();
      if (d <= near_m) pairs.emplace_back(a->first, b->first);
    }
  }
  return pairs;
}

}  // namespace

void FalseMatchOptions::Validate() const {
  Check(fraction >= 0.0 && fraction < 1.0, "fraction", "a share in [0, 1)", fraction);
  Check(near_m > 0.0 && std::isfinite(near_m), "near_m", "a distance > 0 m", near_m);
  Check(max_offset_m >= 1.0 && std::isfinite(max_offset_m), "max_offset_m", "at least 1 m",
        max_offset_m);
  Check(max_yaw_offset_rad >= 0.0 && max_yaw_offset_rad <= M_PI, "max_yaw_offset_rad",
        "an angle in [0, pi] rad", max_yaw_offset_rad);
}

std::vector<GraphFactorRecord> MakeFalseSubmapMatches(
    const std::vector<GraphFactorRecord>& factors, int robot,
    const std::map<int64_t, Eigen::Isometry3d>& T_world_origin, const FalseMatchOptions& options) {
  options.Validate();
  uint64_t next_id = 1;
  double true_matches = 0.0;
  for (const GraphFactorRecord& f : factors) {
    next_id = std::max(next_id, f.id + 1);
    if (f.kind == FactorKind::kSubmapMatch) true_matches += 1.0;
  }
  true_matches = std::max(true_matches, static_cast<double>(T_world_origin.size()) / 5.0);
  const auto wanted = static_cast<std::size_t>(
      std::lround(options.fraction / (1.0 - options.fraction) * true_matches));
  std::vector<std::pair<int64_t, int64_t>> pairs = NearPairs(T_world_origin, options.near_m);
  std::mt19937_64 rng(options.seed);
  std::shuffle(pairs.begin(), pairs.end(), rng);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Matrix6d covariance = MatchCovariance(factors);
  std::vector<GraphFactorRecord> out;
  for (std::size_t k = 0; k < pairs.size() && out.size() < wanted; ++k) {
    const auto [a, b] = pairs[k];
    const Eigen::Isometry3d T_a_b = T_world_origin.at(a).inverse() * T_world_origin.at(b);
    // A wrong offset of 1 to max_offset_m in a random horizontal direction,
    // some height, and a wrong yaw.
    const double heading = 2.0 * M_PI * unit(rng);
    const double offset_m = 1.0 + (options.max_offset_m - 1.0) * unit(rng);
    const Eigen::Vector3d dp(offset_m * std::cos(heading), offset_m * std::sin(heading),
                             0.2 * (unit(rng) - 0.5));
    const double dyaw = options.max_yaw_offset_rad * (2.0 * unit(rng) - 1.0);
    GraphFactorRecord f = SubmapMatchFactor(GraphKey::Origin(robot, a), GraphKey::Origin(robot, b),
                                            T_a_b * GravityAlignedTransform(dp, dyaw), covariance);
    f.id = next_id++;
    out.push_back(std::move(f));
  }
  return out;
}

}  // namespace rover::mapping
