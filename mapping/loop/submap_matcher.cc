#include "mapping/loop/submap_matcher.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <map>
#include <random>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "core/geometry/so3.h"
#include "core/geometry/yaw.h"
#include "mapping/loop/line_spread.h"
#include "mapping/loop/option_checks.h"
#include "mapping/loop/rigid_estimation.h"

namespace rover::mapping {
namespace {

using loop_internal::CheckPositive;
using loop_internal::CheckRange;
using Clock = std::chrono::steady_clock;

double MsSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

double WrapAngle(double a) { return std::remainder(a, 2.0 * M_PI); }

std::string Describe(double value, const char* op, double limit) {
  std::ostringstream s;
  s << value << " " << op << " " << limit;
  return s.str();
}

// The k-sigma box of the prior (frame a) around its translation and yaw.
class PriorBounds {
 public:
  PriorBounds(const MatchPrior& prior, const SubmapMatcherOptions& o)
      : bounded_(prior.bounded), t_(prior.T_a_b.translation()), yaw_(YawOf(prior.T_a_b.linear())) {
    for (std::size_t i = 0; i < 3; ++i) {
      const auto e = static_cast<Eigen::Index>(i);
      bound_[i] = std::max(o.prior_sigma_factor * std::sqrt(std::max(0.0, prior.covariance(e, e))),
                           o.min_bound_m);
    }
    bound_[3] = std::max(o.prior_sigma_factor * std::sqrt(std::max(0.0, prior.covariance(5, 5))),
                         o.min_bound_yaw_rad);
  }

  /// Empty if inside; otherwise which bound was exceeded, and by what.
  std::string Violation(const Eigen::Isometry3d& T) const {
    if (!bounded_) return {};
    static constexpr const char* kAxes[3] = {"x", "y", "z"};
    const Eigen::Vector3d d = T.translation() - t_;
    for (std::size_t i = 0; i < 3; ++i) {
      const double di = std::abs(d[static_cast<Eigen::Index>(i)]);
      if (di > bound_[i]) {
        return std::string("|d") + kAxes[i] + "| " + Describe(di, ">", bound_[i]) + " m";
      }
    }
    const double dyaw = std::abs(WrapAngle(YawOf(T.linear()) - yaw_));
    if (dyaw > bound_[3]) return "|dyaw| " + Describe(dyaw, ">", bound_[3]) + " rad";
    return {};
  }
  bool Inside(const Eigen::Isometry3d& T) const { return Violation(T).empty(); }

 private:
  bool bounded_;
  Eigen::Vector3d t_;
  double yaw_;
  std::array<double, 4> bound_{};
};

// Both directions of the 3-nearest search, deduplicated, sorted by (a, b).
std::vector<KeypointMatch> FindCorrespondences(const SubmapMatchData& a, const SubmapMatchData& b,
                                               const SubmapMatcherOptions& o) {
  std::vector<KeypointMatch> out;
  const auto k = static_cast<std::size_t>(o.nearest_descriptors);
  const auto max_sq = static_cast<float>(o.max_descriptor_distance * o.max_descriptor_distance);
  const auto a_in_b = b.descriptors().Nearest(a.descriptors().descriptors(), k);
  for (std::size_t i = 0; i < a_in_b.size(); ++i) {
    for (const Neighbour& n : a_in_b[i]) {
      if (n.distance_sq <= max_sq) {
        out.push_back({static_cast<uint32_t>(i), n.index, std::sqrt(n.distance_sq)});
      }
    }
  }
  const auto b_in_a = a.descriptors().Nearest(b.descriptors().descriptors(), k);
  for (std::size_t j = 0; j < b_in_a.size(); ++j) {
    for (const Neighbour& n : b_in_a[j]) {
      if (n.distance_sq <= max_sq) {
        out.push_back({n.index, static_cast<uint32_t>(j), std::sqrt(n.distance_sq)});
      }
    }
  }
  std::sort(out.begin(), out.end(), [](const KeypointMatch& x, const KeypointMatch& y) {
    return std::tie(x.a, x.b) < std::tie(y.a, y.b);
  });
  out.erase(std::unique(out.begin(), out.end(),
                        [](const KeypointMatch& x, const KeypointMatch& y) {
                          return x.a == y.a && x.b == y.b;
                        }),
            out.end());
  return out;
}

using BinKey = std::array<int, 3>;

// Hough voting (model -> scene): each correspondence predicts where the
// model's keypoint centroid lies in the scene, through the yaw references
// of its two keypoints. Returns clusters of correspondence indices.
std::vector<std::vector<std::size_t>> HoughClusters(const std::vector<KeypointMatch>& matches,
                                                    const SubmapMatchData& model,
                                                    const SubmapMatchData& scene, bool model_is_a,
                                                    const SubmapMatcherOptions& o) {
  const std::vector<Eigen::Vector3f>& mk = model.keypoints();
  const std::vector<Eigen::Vector3f>& sk = scene.keypoints();
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& p : mk) centroid += p.cast<double>();
  centroid /= static_cast<double>(std::max<std::size_t>(1, mk.size()));

  std::vector<std::pair<BinKey, std::size_t>> votes;
  std::map<BinKey, int> counts;
  const auto strong = [&o](const SubmapMatchData& d, uint32_t i) {
    return static_cast<double>(d.yaw_reference_strength()[i]) >= o.min_yaw_reference_strength;
  };
  for (std::size_t c = 0; c < matches.size(); ++c) {
    const uint32_t m = model_is_a ? matches[c].a : matches[c].b;
    const uint32_t s = model_is_a ? matches[c].b : matches[c].a;
    if (!strong(model, m) || !strong(scene, s)) continue;
    const Eigen::Vector3d local =
        Rz(-model.yaw_reference_rad()[m]) * (centroid - mk[m].cast<double>());
    const Eigen::Vector3d vote = sk[s].cast<double>() + Rz(scene.yaw_reference_rad()[s]) * local;
    BinKey key;
    for (std::size_t i = 0; i < 3; ++i) {
      key[i] = static_cast<int>(std::floor(vote[static_cast<Eigen::Index>(i)] / o.hough_bin_m));
    }
    votes.push_back({key, c});
    ++counts[key];
  }
  // Peaks: most votes first, none adjacent to an earlier one; members are
  // the votes in the peak's 3x3x3 neighbourhood (a vote near a bin border
  // still counts).
  std::vector<std::pair<int, BinKey>> ranked;
  for (const auto& [key, n] : counts) ranked.push_back({n, key});
  std::stable_sort(ranked.begin(), ranked.end(),
                   [](const auto& x, const auto& y) { return x.first > y.first; });
  const auto adjacent = [](const BinKey& x, const BinKey& y) {
    return std::abs(x[0] - y[0]) <= 1 && std::abs(x[1] - y[1]) <= 1 && std::abs(x[2] - y[2]) <= 1;
  };
  std::vector<BinKey> peaks;
  for (const auto& [n, key] : ranked) {
    if (n < o.min_cluster_votes || static_cast<int>(peaks.size()) >= o.max_clusters) break;
    if (std::any_of(peaks.begin(), peaks.end(),
                    [&](const BinKey& p) { return adjacent(p, key); })) {
      continue;
    }
    peaks.push_back(key);
  }
  std::vector<std::vector<std::size_t>> clusters(peaks.size());
  for (const auto& [key, c] : votes) {
    for (std::size_t p = 0; p < peaks.size(); ++p) {
      if (adjacent(peaks[p], key)) clusters[p].push_back(c);
    }
  }
  return clusters;
}

struct Hypothesis {
  Eigen::Isometry3d T_a_b = Eigen::Isometry3d::Identity();
  int inliers = 0;  ///< unique keypoints, the smaller side
  std::vector<std::size_t> inlier_matches;
  int cluster_size = 0;
};

// Inliers of T over all correspondences: the pairs within the distance, and
// the count of unique keypoints (smaller side), so that one keypoint matched
// to three neighbouring ones counts once.
int CountInliers(const Eigen::Isometry3d& T, const std::vector<KeypointMatch>& matches,
                 const SubmapMatchData& a, const SubmapMatchData& b, double distance_m,
                 std::vector<std::size_t>* inlier_matches) {
  const double d_sq = distance_m * distance_m;
  std::vector<uint32_t> ua, ub;
  if (inlier_matches) inlier_matches->clear();
  for (std::size_t c = 0; c < matches.size(); ++c) {
    const Eigen::Vector3d pa = a.keypoints()[matches[c].a].cast<double>();
    const Eigen::Vector3d pb = b.keypoints()[matches[c].b].cast<double>();
    if ((pa - T * pb).squaredNorm() > d_sq) continue;
    ua.push_back(matches[c].a);
    ub.push_back(matches[c].b);
    if (inlier_matches) inlier_matches->push_back(c);
  }
  std::sort(ua.begin(), ua.end());
  std::sort(ub.begin(), ub.end());
  const auto unique_a = std::unique(ua.begin(), ua.end()) - ua.begin();
  const auto unique_b = std::unique(ub.begin(), ub.end()) - ub.begin();
  return static_cast<int>(std::min(unique_a, unique_b));
}

// The best hypothesis of one cluster, refit on its inliers; nullopt-like
// (inliers == 0) if none survived.
Hypothesis RansacCluster(const std::vector<std::size_t>& cluster,
                         const std::vector<KeypointMatch>& matches, const SubmapMatchData& a,
                         const SubmapMatchData& b, const PriorBounds& bounds,
                         const SubmapMatcherOptions& o, std::mt19937_64* rng, int* hypotheses) {
  Hypothesis best;
  best.cluster_size = static_cast<int>(cluster.size());
  const bool four = o.mode == MatchMode::kFourDof;
  const std::size_t sample_size = four ? 2 : 3;
  if (cluster.size() < sample_size) return best;
  const auto pa = [&](std::size_t c) { return a.keypoints()[matches[c].a].cast<double>(); };
  const auto pb = [&](std::size_t c) { return b.keypoints()[matches[c].b].cast<double>(); };
  // Rigid pairs keep their distances; a sample that does not is skipped
  // before any transform is computed.
  const double tolerance = 2.0 * o.inlier_distance_m;
  const auto consistent = [&](std::size_t c1, std::size_t c2) {
    if (matches[c1].a == matches[c2].a || matches[c1].b == matches[c2].b) return false;
    return std::abs((pa(c1) - pa(c2)).norm() - (pb(c1) - pb(c2)).norm()) <= tolerance;
  };
  std::uniform_int_distribution<std::size_t> pick(0, cluster.size() - 1);
  const double inlier_sq = o.inlier_distance_m * o.inlier_distance_m;
  int best_support = 0;
  for (int it = 0; it < o.ransac_iterations; ++it) {
    std::size_t s[3] = {0, 0, 0};
    for (std::size_t k = 0; k < sample_size; ++k) s[k] = cluster[pick(*rng)];
    Eigen::Isometry3d T;
    if (four) {
      if (!consistent(s[0], s[1])) continue;
      if (!TwoPointYawTransform(pa(s[0]), pa(s[1]), pb(s[0]), pb(s[1]), o.min_sample_separation_m,
                                &T)) {
        continue;
      }
    } else {
      if (!consistent(s[0], s[1]) || !consistent(s[0], s[2]) || !consistent(s[1], s[2])) continue;
      if (!FitRigidTransform({pa(s[0]), pa(s[1]), pa(s[2])}, {pb(s[0]), pb(s[1]), pb(s[2])}, &T)) {
        continue;
      }
      if (TiltOf(T.linear()) > o.max_hypothesis_tilt_rad) continue;
    }
    if (!bounds.Inside(T)) continue;
    ++*hypotheses;
    // Scored on the cluster's own correspondences (cheap); the winner's
    // inliers are counted over all of them below.
    int support = 0;
    for (std::size_t c : cluster) support += (pa(c) - T * pb(c)).squaredNorm() <= inlier_sq;
    if (support > best_support) {
      best_support = support;
      best.T_a_b = T;
    }
  }
  if (best_support == 0) return best;
  best.inliers = CountInliers(best.T_a_b, matches, a, b, o.inlier_distance_m, nullptr);
  // Least-squares refit on the inliers, kept if it stays within bounds and
  // does not lose inliers.
  CountInliers(best.T_a_b, matches, a, b, o.inlier_distance_m, &best.inlier_matches);
  std::vector<Eigen::Vector3d> xa, xb;
  for (std::size_t c : best.inlier_matches) {
    xa.push_back(pa(c));
    xb.push_back(pb(c));
  }
  Eigen::Isometry3d refit;
  const bool fitted = four ? FitYawTransform(xa, xb, &refit) : FitRigidTransform(xa, xb, &refit);
  if (fitted && bounds.Inside(refit) &&
      (four || TiltOf(refit.linear()) <= o.max_hypothesis_tilt_rad)) {
    std::vector<std::size_t> refit_matches;
    const int n = CountInliers(refit, matches, a, b, o.inlier_distance_m, &refit_matches);
    if (n >= best.inliers) {
      best.inliers = n;
      best.T_a_b = refit;
      best.inlier_matches = std::move(refit_matches);
    }
  }
  return best;
}

// Inlier keypoints of one side, for the spread check.
std::vector<Eigen::Vector3f> InlierKeypoints(const Hypothesis& h,
                                             const std::vector<KeypointMatch>& matches,
                                             const SubmapMatchData& d, bool side_a) {
  std::vector<uint32_t> ids;
  for (std::size_t c : h.inlier_matches) ids.push_back(side_a ? matches[c].a : matches[c].b);
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  std::vector<Eigen::Vector3f> out;
  for (uint32_t i : ids) out.push_back(d.keypoints()[i]);
  return out;
}

// s^2 H^-1 scaled and floored (adding to the diagonal keeps it positive
// definite); roll and pitch given their own sigma in 4D.
Matrix6d MatchCovariance(const SubmapIcpResult& icp, const SubmapMatcherOptions& o) {
  Matrix6d cov = o.covariance_scale * icp.covariance;
  cov = 0.5 * (cov + cov.transpose());
  const double rp2 = o.roll_pitch_sigma_rad * o.roll_pitch_sigma_rad;
  if (o.mode == MatchMode::kFourDof) {
    cov.row(3).setZero();
    cov.row(4).setZero();
    cov.col(3).setZero();
    cov.col(4).setZero();
    cov(3, 3) = rp2;
    cov(4, 4) = rp2;
  }
  const double sigma_m = std::max(o.min_sigma_m, o.rmse_sigma_factor * icp.rmse_m);
  const double floors[6] = {sigma_m,
                            sigma_m,
                            sigma_m,
                            o.roll_pitch_sigma_rad,
                            o.roll_pitch_sigma_rad,
                            o.min_sigma_yaw_rad};
  for (int i = 0; i < 6; ++i) {
    const double f2 = floors[i] * floors[i];
    if (cov(i, i) < f2) cov(i, i) = f2;
  }
  return cov;
}

void CheckPriorFinite(const MatchPrior& prior) {
  if (!prior.T_a_b.matrix().allFinite()) {
    throw std::invalid_argument(
        "SubmapMatcher::Match: prior.T_a_b has a non-finite entry (expected finite)");
  }
  if (prior.bounded && !prior.covariance.allFinite()) {
    throw std::invalid_argument(
        "SubmapMatcher::Match: prior.covariance has a non-finite entry (expected finite, or "
        "bounded = false)");
  }
}

}  // namespace

void SubmapMatcherOptions::Validate() const {
  constexpr const char* kC = "SubmapMatcherOptions";
  CheckRange(kC, "nearest_descriptors", nearest_descriptors, 1, 100);
  CheckPositive(kC, "max_descriptor_distance", max_descriptor_distance);
  CheckPositive(kC, "hough_bin_m", hough_bin_m);
  CheckRange(kC, "min_cluster_votes", min_cluster_votes, 1, 1e6);
  CheckRange(kC, "max_clusters", max_clusters, 1, 1000);
  CheckRange(kC, "min_yaw_reference_strength", min_yaw_reference_strength, 0.0, 1.0);
  CheckRange(kC, "ransac_iterations", ransac_iterations, 1, 1e7);
  CheckPositive(kC, "inlier_distance_m", inlier_distance_m);
  CheckRange(kC, "min_sample_separation_m", min_sample_separation_m, 0.0, 100.0);
  CheckRange(kC, "max_hypothesis_tilt_rad", max_hypothesis_tilt_rad, 0.0, M_PI);
  CheckPositive(kC, "hypothesis_off_line_distance_m", hypothesis_off_line_distance_m);
  CheckRange(kC, "min_inliers_off_line", min_inliers_off_line, 0, 1e6);
  CheckPositive(kC, "max_line_icp_sigma_m", max_line_icp_sigma_m);
  CheckPositive(kC, "max_line_icp_sigma_yaw_rad", max_line_icp_sigma_yaw_rad);
  CheckPositive(kC, "prior_sigma_factor", prior_sigma_factor);
  CheckRange(kC, "min_bound_m", min_bound_m, 0.0, 1e6);
  CheckRange(kC, "min_bound_yaw_rad", min_bound_yaw_rad, 0.0, M_PI);
  CheckRange(kC, "prior_icp_max_sigma_m", prior_icp_max_sigma_m, 0.0, 10.0);
  CheckRange(kC, "prior_icp_max_sigma_yaw_rad", prior_icp_max_sigma_yaw_rad, 0.0, M_PI);
  CheckRange(kC, "prior_icp_min_overlap_ratio", prior_icp_min_overlap_ratio, 0.0, 1.0);
  CheckRange(kC, "prior_icp_min_obstacle_agreement", prior_icp_min_obstacle_agreement, 0.0, 1.0);
  icp.Validate();
  CheckRange(kC, "icp_passes", icp_passes, 1, 10);
  CheckRange(kC, "min_inliers", min_inliers, 2, 1e6);
  CheckRange(kC, "min_inlier_ratio", min_inlier_ratio, 0.0, 1.0);
  CheckPositive(kC, "max_icp_rmse_m", max_icp_rmse_m);
  CheckRange(kC, "min_overlap_ratio", min_overlap_ratio, 0.0, 1.0);
  CheckRange(kC, "min_obstacle_agreement", min_obstacle_agreement, 0.0, 1.0);
  CheckRange(kC, "min_obstacle_points_near", min_obstacle_points_near, 0, 1e9);
  CheckPositive(kC, "max_icp_shift_m", max_icp_shift_m);
  CheckPositive(kC, "max_icp_turn_rad", max_icp_turn_rad);
  CheckRange(kC, "max_final_tilt_rad", max_final_tilt_rad, 0.0, M_PI);
  CheckRange(kC, "max_yaw_innovation_sigmas", max_yaw_innovation_sigmas, 0.0, 100.0);
  CheckPositive(kC, "covariance_scale", covariance_scale);
  CheckPositive(kC, "min_sigma_m", min_sigma_m);
  CheckRange(kC, "rmse_sigma_factor", rmse_sigma_factor, 0.0, 1e3);
  CheckPositive(kC, "min_sigma_yaw_rad", min_sigma_yaw_rad);
  CheckPositive(kC, "roll_pitch_sigma_rad", roll_pitch_sigma_rad);
}

SubmapMatcherOptions SubmapMatcherOptions::Load(const ConfigNode& node) {
  return Load(node, SubmapMatcherOptions{});
}

SubmapMatcherOptions SubmapMatcherOptions::Load(const ConfigNode& node,
                                                const SubmapMatcherOptions& defaults) {
  SubmapMatcherOptions o = defaults;
  o.mode = node.GetEnum<MatchMode>(
      "mode", {{"four_dof", MatchMode::kFourDof}, {"six_dof", MatchMode::kSixDof}}, o.mode);
  const auto d = [&node](const char* key, double* v) { *v = node.Get<double>(key, *v); };
  const auto i = [&node](const char* key, int* v) { *v = node.Get<int>(key, *v); };
  i("nearest_descriptors", &o.nearest_descriptors);
  d("max_descriptor_distance", &o.max_descriptor_distance);
  d("hough_bin_m", &o.hough_bin_m);
  i("min_cluster_votes", &o.min_cluster_votes);
  i("max_clusters", &o.max_clusters);
  d("min_yaw_reference_strength", &o.min_yaw_reference_strength);
  i("ransac_iterations", &o.ransac_iterations);
  d("inlier_distance_m", &o.inlier_distance_m);
  d("min_sample_separation_m", &o.min_sample_separation_m);
  d("max_hypothesis_tilt_rad", &o.max_hypothesis_tilt_rad);
  d("hypothesis_off_line_distance_m", &o.hypothesis_off_line_distance_m);
  i("min_inliers_off_line", &o.min_inliers_off_line);
  o.line_hypotheses_need_icp =
      node.Get<bool>("line_hypotheses_need_icp", o.line_hypotheses_need_icp);
  d("max_line_icp_sigma_m", &o.max_line_icp_sigma_m);
  d("max_line_icp_sigma_yaw_rad", &o.max_line_icp_sigma_yaw_rad);
  d("prior_sigma_factor", &o.prior_sigma_factor);
  d("min_bound_m", &o.min_bound_m);
  d("min_bound_yaw_rad", &o.min_bound_yaw_rad);
  d("prior_icp_max_sigma_m", &o.prior_icp_max_sigma_m);
  d("prior_icp_max_sigma_yaw_rad", &o.prior_icp_max_sigma_yaw_rad);
  d("prior_icp_min_overlap_ratio", &o.prior_icp_min_overlap_ratio);
  d("prior_icp_min_obstacle_agreement", &o.prior_icp_min_obstacle_agreement);
  if (node.Has("icp")) {
    const ConfigNode icp = node.Child("icp");
    o.icp.metric = icp.GetEnum<IcpMetric>("metric",
                                          {{"point_to_plane", IcpMetric::kPointToPlane},
                                           {"point_to_point", IcpMetric::kPointToPoint}},
                                          o.icp.metric);
    o.icp.max_iterations = icp.Get<int>("max_iterations", o.icp.max_iterations);
    o.icp.initial_distance_m = icp.Get<double>("initial_distance_m", o.icp.initial_distance_m);
    o.icp.final_distance_m = icp.Get<double>("final_distance_m", o.icp.final_distance_m);
    o.icp.convergence_m = icp.Get<double>("convergence_m", o.icp.convergence_m);
    o.icp.convergence_rad = icp.Get<double>("convergence_rad", o.icp.convergence_rad);
    o.icp.min_correspondences = icp.Get<int>("min_correspondences", o.icp.min_correspondences);
    o.icp.robust_scale_m = icp.Get<double>("robust_scale_m", o.icp.robust_scale_m);
    o.icp.max_normal_angle_deg =
        icp.Get<double>("max_normal_angle_deg", o.icp.max_normal_angle_deg);
    o.icp.obstacle_agreement_distance_m =
        icp.Get<double>("obstacle_agreement_distance_m", o.icp.obstacle_agreement_distance_m);
  }
  i("icp_passes", &o.icp_passes);
  i("min_inliers", &o.min_inliers);
  d("min_inlier_ratio", &o.min_inlier_ratio);
  d("max_icp_rmse_m", &o.max_icp_rmse_m);
  d("min_overlap_ratio", &o.min_overlap_ratio);
  d("min_obstacle_agreement", &o.min_obstacle_agreement);
  i("min_obstacle_points_near", &o.min_obstacle_points_near);
  d("max_icp_shift_m", &o.max_icp_shift_m);
  d("max_icp_turn_rad", &o.max_icp_turn_rad);
  d("max_final_tilt_rad", &o.max_final_tilt_rad);
  d("max_yaw_innovation_sigmas", &o.max_yaw_innovation_sigmas);
  d("covariance_scale", &o.covariance_scale);
  d("min_sigma_m", &o.min_sigma_m);
  d("rmse_sigma_factor", &o.rmse_sigma_factor);
  d("min_sigma_yaw_rad", &o.min_sigma_yaw_rad);
  d("roll_pitch_sigma_rad", &o.roll_pitch_sigma_rad);
  o.seed = node.Get<uint64_t>("seed", o.seed);
  o.Validate();
  return o;
}

SubmapMatcher::SubmapMatcher(const SubmapMatcherOptions& options) : options_(options) {
  options_.Validate();
}

namespace {

// Steps 1-3: correspondences, Hough clusters, RANSAC. Empty when a hypothesis
// (r->T_a_b_initial) was found, else why not.
std::string FindHypothesis(const SubmapMatcherOptions& o, const SubmapMatchData& a,
                           const SubmapMatchData& b, const MatchPrior& prior,
                           const PriorBounds& bounds, SubmapMatchResult* result) {
  SubmapMatchResult& r = *result;
  // 1. Correspondences.
  Clock::time_point ts = Clock::now();
  r.correspondences = FindCorrespondences(a, b, o);
  r.timings.correspondences_ms = MsSince(ts);
  const int n_matches = static_cast<int>(r.correspondences.size());
  if (n_matches < o.min_inliers) {
    return "correspondences " + Describe(n_matches, "<", o.min_inliers);
  }

  // 2. Hough voting both ways.
  ts = Clock::now();
  std::vector<std::vector<std::size_t>> clusters = HoughClusters(r.correspondences, a, b, true, o);
  for (auto& c : HoughClusters(r.correspondences, b, a, false, o)) clusters.push_back(std::move(c));
  r.clusters = static_cast<int>(clusters.size());
  r.timings.hough_ms = MsSince(ts);
  if (clusters.empty()) {
    return "no Hough cluster with >= " + std::to_string(o.min_cluster_votes) + " votes";
  }

  // 3. RANSAC per cluster; the best by inliers among those spread beyond a
  // line on both sides.
  ts = Clock::now();
  std::mt19937_64 rng(o.seed);
  Hypothesis best;
  Hypothesis best_on_a_line;
  for (const std::vector<std::size_t>& cluster : clusters) {
    Hypothesis h = RansacCluster(cluster, r.correspondences, a, b, bounds, o, &rng, &r.hypotheses);
    if (h.inliers <= best.inliers) continue;
    const auto seed = o.seed + static_cast<uint64_t>(h.inliers);
    if (CountOffLine(InlierKeypoints(h, r.correspondences, a, true),
                     o.hypothesis_off_line_distance_m, 500, seed) < o.min_inliers_off_line ||
        CountOffLine(InlierKeypoints(h, r.correspondences, b, false),
                     o.hypothesis_off_line_distance_m, 500, seed) < o.min_inliers_off_line) {
      if (h.inliers > best_on_a_line.inliers) best_on_a_line = std::move(h);
      continue;
    }
    best = std::move(h);
  }
  r.timings.ransac_ms = MsSince(ts);
  if (best.inliers == 0 && best_on_a_line.inliers > 0) {
    // Without bounds nothing stops the ICP sliding along the line: its
    // s^2 H^-1 does not show that freedom (a wall on flat ground: 2 mm).
    if (!o.line_hypotheses_need_icp || !prior.bounded) {
      return "inlier keypoints of every hypothesis along a line";
    }
    best = std::move(best_on_a_line);
    r.inliers_on_a_line = true;
  }
  if (best.inliers == 0) {
    return r.hypotheses == 0 ? "no RANSAC hypothesis within the prior's bounds"
                             : "no RANSAC hypothesis with inliers";
  }
  r.T_a_b_initial = best.T_a_b;
  for (std::size_t c : best.inlier_matches) r.inliers.push_back(r.correspondences[c]);
  r.inlier_ratio = static_cast<double>(best.inlier_matches.size()) / n_matches;
  if (best.inliers < o.min_inliers) {
    r.inliers_on_a_line = false;
    return "RANSAC inliers " + Describe(best.inliers, "<", o.min_inliers);
  }
  if (r.inlier_ratio < o.min_inlier_ratio) {
    r.inliers_on_a_line = false;
    return "inlier ratio " + Describe(r.inlier_ratio, "<", o.min_inlier_ratio);
  }
  return {};
}

// The yaw innovation gate (SubmapMatcherOptions::max_yaw_innovation_sigmas):
// empty when the match's yaw agrees with a bounded prior's.
std::string YawInnovationRejection(const SubmapMatcherOptions& o, const MatchPrior& prior,
                                   const SubmapMatchResult& r) {
  if (!prior.bounded || o.max_yaw_innovation_sigmas <= 0.0) return {};
  const double innovation_rad = std::abs(YawOf((prior.T_a_b.inverse() * r.T_a_b).linear()));
  const double sigma_rad = std::sqrt(prior.covariance(5, 5));
  const double limit_rad = o.max_yaw_innovation_sigmas * sigma_rad;
  if (innovation_rad <= limit_rad) return {};
  std::ostringstream text;
  text << "yaw " << innovation_rad << " rad off the prior's > " << limit_rad << " rad ("
       << o.max_yaw_innovation_sigmas << " sigma of the prior's " << sigma_rad << ")";
  return text.str();
}

// Steps 4-5: ICP from r->T_a_b_initial, then the validity checks. Empty when
// the match is accepted, else the first check that failed.
std::string RefineAndCheck(const SubmapMatcherOptions& o, const SubmapMatchData& a,
                           const SubmapMatchData& b, const MatchPrior& prior,
                           const PriorBounds& bounds, SubmapMatchResult* result) {
  SubmapMatchResult& r = *result;
  // 4. ICP.
  const Clock::time_point ts = Clock::now();
  const Eigen::Isometry3d start = r.T_a_b_initial;
  r.icp = AlignSubmaps(a, b, start, o.mode == MatchMode::kFourDof, o.icp);
  // Restarting from its own result (the correspondence distance and the
  // Cauchy scale anneal again) lets the ICP leave a shallow minimum that
  // the coarse RANSAC start led it into.
  for (int pass = 1; pass < o.icp_passes && r.icp.ok; ++pass) {
    SubmapIcpResult again = AlignSubmaps(a, b, r.icp.T_a_b, o.mode == MatchMode::kFourDof, o.icp);
    if (!again.ok) break;
    r.icp = again;
  }
  r.timings.icp_ms = MsSince(ts);
  r.T_a_b = r.icp.T_a_b;
  if (!r.icp.ok) {
    return "ICP failed (" + std::to_string(r.icp.correspondences) +
           " correspondences or a degenerate Hessian)";
  }
  const std::size_t smaller = std::min(a.icp_points().size(), b.icp_points().size());
  r.overlap_ratio = std::min(1.0, static_cast<double>(r.icp.overlap_points) /
                                      static_cast<double>(std::max<std::size_t>(1, smaller)));

  // 5. Validity.
  const double shift = (r.icp.T_a_b.translation() - start.translation()).norm();
  if (shift > o.max_icp_shift_m) {
    return "ICP moved " + Describe(shift, ">", o.max_icp_shift_m) + " m";
  }
  const double turn = LogSO3(start.linear().transpose() * r.icp.T_a_b.linear()).norm();
  if (turn > o.max_icp_turn_rad) {
    return "ICP turned " + Describe(turn, ">", o.max_icp_turn_rad) + " rad";
  }
  if (r.icp.rmse_m > o.max_icp_rmse_m) {
    return "ICP RMSE " + Describe(r.icp.rmse_m, ">", o.max_icp_rmse_m) + " m";
  }
  const double min_overlap = r.from_prior ? o.prior_icp_min_overlap_ratio : o.min_overlap_ratio;
  if (r.overlap_ratio < min_overlap) {
    return "overlap " + Describe(r.overlap_ratio, "<", min_overlap);
  }
  r.obstacle_agreement =
      r.icp.obstacle_points_near > 0
          ? static_cast<double>(r.icp.obstacle_points_agreeing) / r.icp.obstacle_points_near
          : 0.0;
  if (r.icp.obstacle_points_near < o.min_obstacle_points_near) {
    return "obstacle points near a " +
           Describe(r.icp.obstacle_points_near, "<", o.min_obstacle_points_near);
  }
  const double min_agreement =
      r.from_prior ? o.prior_icp_min_obstacle_agreement : o.min_obstacle_agreement;
  if (r.obstacle_agreement < min_agreement) {
    return "obstacle agreement " + Describe(r.obstacle_agreement, "<", min_agreement);
  }
  if (r.inliers_on_a_line || r.from_prior) {
    // The keypoints leave the match free along their line (or in yaw about
    // it), or there are no keypoints at all: the whole cloud, ground relief
    // included, has to fix it.
    const double sigma_m = std::sqrt(std::max(r.icp.covariance(0, 0), r.icp.covariance(1, 1)));
    const double sigma_yaw = std::sqrt(r.icp.covariance(5, 5));
    const char* why = r.from_prior ? "aligned from the prior" : "inlier keypoints along a line";
    if (sigma_m > o.max_line_icp_sigma_m) {
      return std::string(why) + " and the ICP's xy sigma " +
             Describe(sigma_m, ">", o.max_line_icp_sigma_m) + " m";
    }
    if (sigma_yaw > o.max_line_icp_sigma_yaw_rad) {
      return std::string(why) + " and the ICP's yaw sigma " +
             Describe(sigma_yaw, ">", o.max_line_icp_sigma_yaw_rad) + " rad";
    }
  }
  const std::string outside = bounds.Violation(r.T_a_b);
  if (!outside.empty()) return "final transform outside the prior's bounds: " + outside;
  if (o.mode == MatchMode::kSixDof) {
    const double tilt = TiltOf(r.T_a_b.linear());
    if (tilt > o.max_final_tilt_rad) {
      return "tilt " + Describe(tilt, ">", o.max_final_tilt_rad) + " rad";
    }
  }
  r.covariance = MatchCovariance(r.icp, o);
  return YawInnovationRejection(o, prior, r);
}

// The prior is tight enough for an ICP started from it to converge to the
// right basin: x, y within prior_icp_max_sigma_m, yaw within
// prior_icp_max_sigma_yaw_rad (standard deviations, frame a).
bool PriorAllowsLocalIcp(const MatchPrior& prior, const SubmapMatcherOptions& o) {
  if (!prior.bounded || o.prior_icp_max_sigma_m <= 0.0) return false;
  const double sigma_xy = std::sqrt(std::max(prior.covariance(0, 0), prior.covariance(1, 1)));
  return sigma_xy <= o.prior_icp_max_sigma_m &&
         std::sqrt(prior.covariance(5, 5)) <= o.prior_icp_max_sigma_yaw_rad;
}

}  // namespace

SubmapMatchResult SubmapMatcher::Match(const SubmapMatchData& a, const SubmapMatchData& b,
                                       const MatchPrior& prior) const {
  const SubmapMatcherOptions& o = options_;
  CheckPriorFinite(prior);
  SubmapMatchResult r;
  const Clock::time_point t0 = Clock::now();
  const auto finish = [&](std::string rejection) {
    r.rejection = std::move(rejection);
    r.accepted = r.rejection.empty();
    r.timings.total_ms = MsSince(t0);
    return r;
  };
  if (!a.suitable()) return finish("submap a unsuitable: " + a.suitability_reason());
  if (!b.suitable()) return finish("submap b unsuitable: " + b.suitability_reason());
  if (a.descriptors().descriptors().cols() != b.descriptors().descriptors().cols()) {
    throw std::invalid_argument("SubmapMatcher::Match: descriptor lengths differ (a: " +
                                std::to_string(a.descriptors().descriptors().cols()) +
                                ", b: " + std::to_string(b.descriptors().descriptors().cols()) +
                                "); build both with the same descriptor options");
  }
  const PriorBounds bounds(prior, o);
  std::string no_hypothesis = FindHypothesis(o, a, b, prior, bounds, &r);
  if (!no_hypothesis.empty()) {
    if (!PriorAllowsLocalIcp(prior, o)) return finish(std::move(no_hypothesis));
    // The graph already knows the pair to within the ICP's basin: align the
    // clouds from the prior (the keypoints failed, e.g. the two submaps saw
    // the rocks from opposite sides), under stricter checks below.
    r.from_prior = true;
    r.T_a_b_initial = prior.T_a_b;
    r.inliers.clear();  // of a hypothesis that failed
    r.inlier_ratio = 0.0;
    const std::string rejection = RefineAndCheck(o, a, b, prior, bounds, &r);
    return finish(rejection.empty() ? rejection
                                    : no_hypothesis + "; aligned from the prior: " + rejection);
  }
  return finish(RefineAndCheck(o, a, b, prior, bounds, &r));
}

}  // namespace rover::mapping
