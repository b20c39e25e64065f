#include "hil/sim/experiments/tag_evaluation.h"

#include <cmath>
#include <cstdio>
#include <map>

#include "core/log/msgs/builtin_interfaces.h"
#include "core/stats/percentile.h"
#include "mapping/slam/graph_log.h"
#include "mapping/tags/tag_pose_errors.h"

namespace rover::sim::experiments {
namespace {

constexpr double kChi2Six95 = 12.592;
constexpr double kChi2Three95 = 7.815;
constexpr double kDeg = M_PI / 180.0;

// T_world_tag of every tag on a static carrier, by id.
std::map<int, Eigen::Isometry3d> StaticTags(const World& world) {
  std::map<int, Eigen::Isometry3d> tags;
  for (const TagCarrier& carrier : world.carriers) {
    if (!carrier.is_static) continue;
    for (const TagMarker& tag : carrier.tags) {
      tags[tag.id] = carrier.T_world_carrier * tag.T_carrier_tag;
    }
  }
  return tags;
}

}  // namespace

TagScore ScoreTagDetections(const std::vector<log::rover_msgs::TagDetection>& detections,
                            const World& world,
                            const std::function<Eigen::Isometry3d(Time)>& T_world_cam_at) {
  const std::map<int, Eigen::Isometry3d> tags = StaticTags(world);
  TagScore s;
  std::vector<double> nees, position_pct, rotation_deg;
  for (const log::rover_msgs::TagDetection& d : detections) {
    ++s.decoded;
    if (!d.accepted) continue;
    ++s.accepted;
    const auto tag = tags.find(d.id);
    if (tag == tags.end()) continue;
    const Eigen::Isometry3d T_cam_tag_true =
        T_world_cam_at(log::FromRosTime(d.header.stamp)).inverse() * tag->second;
    const mapping::TagPoseErrors e =
        mapping::TagPoseError(mapping::FromPoseMsg(d.pose), T_cam_tag_true);
    mapping::Matrix6d covariance;
    for (int i = 0; i < 36; ++i)
      covariance(i / 6, i % 6) = d.covariance[static_cast<std::size_t>(i)];
    const double distance_m = T_cam_tag_true.translation().norm();
    ++s.scored;
    const double x = e.dot(covariance.ldlt().solve(e));
    nees.push_back(x);
    s.nees_in_bound += x <= kChi2Six95;
    position_pct.push_back(100.0 * e.head<3>().norm() / distance_m);
    rotation_deg.push_back(e.tail<3>().norm() / kDeg);
    const bool wrong = e.tail<3>().norm() > 20.0 * kDeg;
    s.wrong_solutions += wrong;
    const Eigen::Vector3d e_rotation = e.tail<3>();
    const Eigen::Matrix3d rotation_covariance = covariance.bottomRightCorner<3, 3>();
    const double rotation_nees = e_rotation.dot(rotation_covariance.ldlt().solve(e_rotation));
    s.wrong_solutions_claimed += wrong && rotation_nees > kChi2Three95;
    if (wrong) {
      s.wrong.push_back({log::FromRosTime(d.header.stamp), d.id, distance_m, d.tilt_rad / kDeg,
                         d.ambiguity_ratio, d.flipped, e.tail<3>().norm() / kDeg, rotation_nees});
    }
    s.normalized_rms += e.cwiseQuotient(covariance.diagonal().cwiseSqrt()).cwiseAbs2();
    s.mean_position_error_m += e.head<3>();
  }
  if (s.scored == 0) return s;
  s.normalized_rms = (s.normalized_rms / static_cast<double>(s.scored)).cwiseSqrt();
  s.mean_position_error_m /= static_cast<double>(s.scored);
  s.nees_in_bound_pct =
      100.0 * static_cast<double>(s.nees_in_bound) / static_cast<double>(s.scored);
  s.nees_median = stats::Percentile(nees, 50.0);
  double sum = 0.0;
  for (const double x : nees) sum += x;
  s.nees_mean = sum / static_cast<double>(nees.size());
  s.position_error_pct_median = stats::Percentile(position_pct, 50.0);
  s.rotation_error_deg_median = stats::Percentile(rotation_deg, 50.0);
  return s;
}

void ReportTagScore(const TagScore& s, std::ostream& report) {
  char text[600];
  std::snprintf(text, sizeof(text),
                "  tags vs truth: %llu observations logged, %llu accepted, %llu on landmarks "
                "scored: NEES within the chi^2(6) 95 %% bound for %.1f %% (median %.2f, mean "
                "%.2f; 6 if consistent), error median %.2f %% of the distance and %.2f deg, %llu "
                "wrong solutions (%llu whose rotation covariance does not cover them); error over "
                "sigma (RMS) x "
                "%.2f y %.2f z %.2f, roll %.2f pitch "
                "%.2f yaw %.2f; mean position error %+.1f %+.1f %+.1f mm (camera)\n",
                static_cast<unsigned long long>(s.decoded),
                static_cast<unsigned long long>(s.accepted),
                static_cast<unsigned long long>(s.scored), s.nees_in_bound_pct, s.nees_median,
                s.nees_mean, s.position_error_pct_median, s.rotation_error_deg_median,
                static_cast<unsigned long long>(s.wrong_solutions),
                static_cast<unsigned long long>(s.wrong_solutions_claimed), s.normalized_rms(0),
                s.normalized_rms(1), s.normalized_rms(2), s.normalized_rms(3), s.normalized_rms(4),
                s.normalized_rms(5), 1e3 * s.mean_position_error_m.x(),
                1e3 * s.mean_position_error_m.y(), 1e3 * s.mean_position_error_m.z());
  report << text;
  for (const WrongTagSolution& w : s.wrong) {
    std::snprintf(text, sizeof(text),
                  "    wrong solution: tag %d at %.3f s, %.2f m, tilt %+.1f deg, ambiguity ratio "
                  "%.2f, %u of 256 perturbed poses flipped; rotation off by %.1f deg, NEES %.1f "
                  "(%s)\n",
                  w.id, w.stamp.ToSeconds(), w.distance_m, w.tilt_deg, w.ambiguity_ratio, w.flipped,
                  w.rotation_error_deg, w.rotation_nees,
                  w.rotation_nees > kChi2Three95 ? "claimed" : "covered");
    report << text;
  }
}

}  // namespace rover::sim::experiments
