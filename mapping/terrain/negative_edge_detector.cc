#include "mapping/terrain/negative_edge_detector.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace rover::mapping {
namespace {

bool HasPoint(DepthState s) { return s == DepthState::kValid || s == DepthState::kUncertain; }

}  // namespace

void NegativeEdgeOptions::Validate() const {
  if (!(std::isfinite(depth_jump_m) && depth_jump_m > 0.0)) {
    throw std::invalid_argument("NegativeEdgeOptions.depth_jump_m: expected > 0, found " +
                                std::to_string(depth_jump_m));
  }
  if (!(std::isfinite(out_of_range_distance_m) && out_of_range_distance_m > 0.0)) {
    throw std::invalid_argument(
        "NegativeEdgeOptions.out_of_range_distance_m: expected > 0, found " +
        std::to_string(out_of_range_distance_m));
  }
  if (!(max_slope_deg > 0.0 && max_slope_deg < 90.0)) {
    throw std::invalid_argument("NegativeEdgeOptions.max_slope_deg: expected in (0, 90), found " +
                                std::to_string(max_slope_deg));
  }
}

NegativeEdgeDetector::NegativeEdgeDetector(const NegativeEdgeOptions& options)
    : options_(options), max_slope_(std::tan(options.max_slope_deg * M_PI / 180.0)) {
  options_.Validate();
}

std::vector<NegativeEdge> NegativeEdgeDetector::Detect(
    const DepthImage& depth, const Eigen::Isometry3d& T_gravity_cam) const {
  std::vector<NegativeEdge> edges;
  const Eigen::Matrix3d& R = T_gravity_cam.linear();
  for (int u = 0; u < depth.width(); ++u) {
    for (int v = 1; v < depth.height(); ++v) {
      // The near side must be a point within the error budget (thesis: too
      // uncertain points are left out of all later processing); the far
      // side may be uncertain, as the ground below a cliff is far away.
      if (depth.state(u, v) != DepthState::kValid) continue;
      const DepthState upper = depth.state(u, v - 1);
      const Eigen::Vector3d q_cam = depth.point(u, v).cast<double>();
      const Eigen::Vector3d q = T_gravity_cam * q_cam;
      if (HasPoint(upper)) {
        const Eigen::Vector3d p_cam = depth.point(u, v - 1).cast<double>();
        // A jump, and one that the two depths' stereo error does not explain.
        double jump_m = options_.depth_jump_m;
        if (options_.error_adaptive) {
          jump_m += std::hypot(static_cast<double>(depth.depth_sigma(u, v - 1)),
                               static_cast<double>(depth.depth_sigma(u, v)));
        }
        if (p_cam.z() - q_cam.z() <= jump_m) continue;
        const Eigen::Vector3d p = T_gravity_cam * p_cam;
        const double run = (q.head<2>() - p.head<2>()).norm();
        const double drop = q.z() - p.z();
        const double slope = run > 1e-9 ? drop / run : std::numeric_limits<double>::infinity();
        if (drop > 0.0 && slope > max_slope_) edges.push_back({u, v, q, slope});
      } else if (upper == DepthState::kInfinite && options_.flag_out_of_range) {
        // Where would ground level with q cross the upper pixel's ray? If
        // well within stereo range, the ground there must lie lower.
        const Eigen::Vector3d ray = R * depth.Ray(u, v - 1).normalized();
        const Eigen::Vector3d camera = T_gravity_cam.translation();
        if (ray.z() < 0.0 && q.z() < camera.z()) {
          const double distance = (q.z() - camera.z()) / ray.z();
          if (distance < options_.out_of_range_distance_m) {
            edges.push_back({u, v, q, std::numeric_limits<double>::infinity()});
          }
        }
      }
    }
  }
  return edges;
}

}  // namespace rover::mapping
