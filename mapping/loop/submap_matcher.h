#ifndef ROVER_MAPPING_LOOP_SUBMAP_MATCHER_H_
#define ROVER_MAPPING_LOOP_SUBMAP_MATCHER_H_

// Pairwise submap matching (thesis section 6.1.2): the relative transform
// T_a_b between two submap origins (p_a = T_a_b * p_b) with an uncertainty,
// or a reason why there is none.
//   1. Correspondences: each keypoint's 3 most similar descriptors in the
//      other submap, both ways, within max_descriptor_distance.
//   2. Hough voting of translations (Tombari & Di Stefano 2010), a -> b and
//      b -> a: each correspondence, through its keypoints' yaw references,
//      votes for where the other submap's keypoint centroid lies; bins with
//      enough votes become clusters.
//   3. RANSAC per cluster. 4D (the thesis's method): two-point hypotheses
//      over x, y, z, yaw (eq. 6.5-6.7). 6D (the baseline, options.mode =
//      kSixDof): three-point SVD hypotheses, tilt > 10 deg dropped.
//      Hypotheses outside the prior's k-sigma bounds are dropped; each is
//      scored on its cluster, the cluster's best is refit on its inliers
//      counted over all correspondences (unique keypoints on both sides,
//      so one keypoint matched to three neighbours counts once); one whose
//      inlier keypoints lie along a line (line_spread.h) is dropped. The
//      best one by inliers wins.
//   4. ICP on the full clouds (submap_icp.h), 4D or 6D.
//   3b. With no hypothesis and a tight prior, the ICP starts from the prior
//      (stricter checks; see prior_icp_max_sigma_m).
//   5. Validity: RANSAC inliers and inlier ratio, ICP residual, overlap,
//      obstacle agreement (b's obstacles must land on a's obstacles, not on
//      a's ground: flat ground aligns anywhere, rocks do not), the final
//      transform within the prior's bounds, and in 6D tilt <= 1 deg.
// A Match() call keeps no state: it is const and may run concurrently on
// any number of threads; its randomness is seeded from options.seed only,
// so equal inputs give equal results.

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/config/config.h"
#include "mapping/graph/pose_graph.h"
#include "mapping/loop/submap_icp.h"
#include "mapping/loop/submap_match_data.h"

namespace rover::mapping {

/// What the graph believes of T_a_b before matching.
struct MatchPrior {
  Eigen::Isometry3d T_a_b = Eigen::Isometry3d::Identity();
  /// Over [dp (frame a); dtheta (right)] (RoverGraph's convention). Only the
  /// x, y, z and yaw variances bound the search.
  Matrix6d covariance = Matrix6d::Identity();
  /// False: search without bounds (the covariance is ignored).
  bool bounded = true;

  /// A prior that bounds nothing.
  static MatchPrior Unbounded(const Eigen::Isometry3d& T_a_b = Eigen::Isometry3d::Identity()) {
    MatchPrior p;
    p.T_a_b = T_a_b;
    p.bounded = false;
    return p;
  }
};

enum class MatchMode {
  kFourDof,  ///< thesis: 4D RANSAC + 4D ICP
  kSixDof,   ///< baseline: 6D RANSAC + 6D ICP, then the tilt checks
};

struct SubmapMatcherOptions {
  MatchMode mode = MatchMode::kFourDof;
  /// Correspondences: k most similar each way, L2 distance of the unit
  /// descriptors at most this.
  int nearest_descriptors = 3;
  double max_descriptor_distance = 0.25;
  /// Hough voting: bin edge, votes a bin needs to become a cluster, and at
  /// most this many clusters per direction (most votes first).
  double hough_bin_m = 0.5;
  int min_cluster_votes = 4;
  int max_clusters = 8;
  /// Keypoints whose yaw reference is weaker than this do not vote.
  double min_yaw_reference_strength = 0.15;
  /// RANSAC: samples per cluster, inlier distance, and the minimum xy
  /// separation of a two-point sample (its direction defines the yaw).
  int ransac_iterations = 300;
  double inlier_distance_m = 0.3;
  double min_sample_separation_m = 0.5;
  /// 6D: hypotheses tilted more than this are dropped (thesis: 10 deg).
  double max_hypothesis_tilt_rad = 10.0 * M_PI / 180.0;
  /// Inlier keypoints beyond a line (per side): at least this many farther
  /// than this from the best line.
  double hypothesis_off_line_distance_m = 0.5;
  int min_inliers_off_line = 3;
  /// When every hypothesis's inliers lie along a line: true takes the best
  /// of them on to the ICP and accepts only if the ICP's s^2 H^-1 (before
  /// the floors) is well conditioned, x and y sigma (frame a) at most
  /// max_line_icp_sigma_m and yaw at most max_line_icp_sigma_yaw_rad: ground
  /// relief and the other structure of the whole cloud can fix what a row of
  /// keypoints leaves free. Only with a bounded prior: s^2 H^-1 does not
  /// show the freedom along a wall on flat ground, the prior's bounds stop
  /// the slide. false rejects such a pair.
  bool line_hypotheses_need_icp = true;
  double max_line_icp_sigma_m = 0.005;
  double max_line_icp_sigma_yaw_rad = 0.08 * M_PI / 180.0;
  /// Prior bounds: |x - x_prior| <= max(k sigma_x, min_bound_m) in frame a,
  /// likewise y, z, and yaw with min_bound_yaw_rad.
  double prior_sigma_factor = 3.0;
  double min_bound_m = 0.3;
  double min_bound_yaw_rad = 3.0 * M_PI / 180.0;
  /// When the keypoints give no hypothesis but the prior is tight (x and y
  /// standard deviations at most prior_icp_max_sigma_m, yaw at most
  /// prior_icp_max_sigma_yaw_rad), the ICP starts from the prior: two
  /// submaps that saw the same rocks from opposite sides share few
  /// descriptors, yet their clouds overlap. Such a match must pass the
  /// stricter overlap and obstacle agreement below and the conditioning test
  /// of line hypotheses (max_line_icp_sigma_*). 0 turns it off.
  double prior_icp_max_sigma_m = 0.2;
  double prior_icp_max_sigma_yaw_rad = 1.0 * M_PI / 180.0;
  double prior_icp_min_overlap_ratio = 0.5;
  double prior_icp_min_obstacle_agreement = 0.45;
  /// Refinement, run icp_passes times, each from the previous result.
  SubmapIcpOptions icp;
  int icp_passes = 2;
  /// Validity.
  int min_inliers = 6;
  double min_inlier_ratio = 0.05;
  double max_icp_rmse_m = 0.08;
  double min_overlap_ratio = 0.25;
  /// Of b's obstacle points that land near a's cloud, the share landing on
  /// a's obstacles (SubmapIcpResult::obstacle_points_agreeing), and the
  /// least number of them.
  double min_obstacle_agreement = 0.5;
  int min_obstacle_points_near = 20;
  /// ICP must not move further than this from the RANSAC hypothesis (a jump
  /// means it fell into another basin).
  double max_icp_shift_m = 1.0;
  double max_icp_turn_rad = 10.0 * M_PI / 180.0;
  /// 6D: tilt after the ICP at most this (thesis: 1 deg).
  double max_final_tilt_rad = 1.0 * M_PI / 180.0;
  /// Innovation gate on yaw, with a bounded prior: the match's yaw may
  /// differ from the prior's by at most this many of the prior's yaw
  /// standard deviations. Where the graph already knows the relative heading
  /// better than the matcher measures it, a match a degree off it is the
  /// matcher's error (each submap saw other sides of the rocks), not news:
  /// the matcher's yaw errors have a long tail (median 0.36 deg, p90 0.9 deg
  /// on a 1 km figure-eight) that its floored sigma (min_sigma_yaw_rad)
  /// cannot describe, so the match's own variance is left out of the test.
  /// After a long drift the prior's variance opens the gate. The prior's
  /// bounds (prior_sigma_factor, min_bound_yaw_rad) only confine the search.
  /// It needs frame switches whose yaw covariance is consistent over many
  /// switches: with a biased heading the graph is overconfident and refuses
  /// valid closures. 0 turns it off (the library's default).
  double max_yaw_innovation_sigmas = 0.0;
  /// Covariance of an accepted match: the ICP's s^2 H^-1 scaled by
  /// covariance_scale, each standard deviation floored, roll and pitch (4D)
  /// given roll_pitch_sigma_rad: the origins are gravity-aligned up to the
  /// filter's tilt error. s^2 H^-1 treats thousands of neighbouring stereo
  /// points as independent and misses the systematic part (each submap sees
  /// other sides of the rocks), so it is far too small on its own; the
  /// translation floor is the larger of min_sigma_m and rmse_sigma_factor
  /// times the ICP's RMSE (the thesis derives the uncertainty from the
  /// RMSE), so that noisier matches weigh less. rover-sim loop measures the
  /// consistency of the result against ground truth.
  double covariance_scale = 1.0;
  double min_sigma_m = 0.04;
  double rmse_sigma_factor = 2.5;
  double min_sigma_yaw_rad = 0.4 * M_PI / 180.0;
  double roll_pitch_sigma_rad = 0.005;
  uint64_t seed = 1;

  /// Throws std::invalid_argument "SubmapMatcherOptions.<key>: ...".
  void Validate() const;
  /// Keys as the fields (mode: four_dof | six_dof; icp: a child map with
  /// metric point_to_plane | point_to_point and the SubmapIcpOptions keys);
  /// a key the node does not name keeps its value in `defaults`.
  static SubmapMatcherOptions Load(const ConfigNode& node, const SubmapMatcherOptions& defaults);
  /// As above, over the library's defaults.
  static SubmapMatcherOptions Load(const ConfigNode& node);
};

/// One keypoint correspondence: indices into a's and b's keypoints.
struct KeypointMatch {
  uint32_t a = 0;
  uint32_t b = 0;
  float descriptor_distance = 0.0f;
};

struct MatchTimings {
  double correspondences_ms = 0.0;
  double hough_ms = 0.0;
  double ransac_ms = 0.0;
  double icp_ms = 0.0;
  double total_ms = 0.0;
};

struct SubmapMatchResult {
  bool accepted = false;
  /// Why not (empty when accepted): the first check that failed, with the
  /// value and the limit.
  std::string rejection;
  /// Origin a to origin b: p_a = T_a_b * p_b.
  Eigen::Isometry3d T_a_b = Eigen::Isometry3d::Identity();
  /// Over [dp (frame a); dtheta (right)], for RoverGraph::AddSubmapMatch.
  Matrix6d covariance = Matrix6d::Identity();
  /// All descriptor correspondences, and the RANSAC inliers of the winner.
  std::vector<KeypointMatch> correspondences;
  std::vector<KeypointMatch> inliers;
  int clusters = 0;
  int hypotheses = 0;  ///< RANSAC hypotheses inside the prior's bounds
  /// The winner's inlier keypoints lie along a line (then the ICP's
  /// conditioning decided).
  bool inliers_on_a_line = false;
  /// No keypoint hypothesis: the ICP started from the prior
  /// (SubmapMatcherOptions::prior_icp_max_sigma_m).
  bool from_prior = false;
  double inlier_ratio = 0.0;  ///< inliers / correspondences of the winning cluster
  /// The RANSAC winner before refinement.
  Eigen::Isometry3d T_a_b_initial = Eigen::Isometry3d::Identity();
  SubmapIcpResult icp;
  /// Share of the smaller ICP subsample that found a partner.
  double overlap_ratio = 0.0;
  /// obstacle_points_agreeing / obstacle_points_near of the ICP result.
  double obstacle_agreement = 0.0;
  MatchTimings timings;
};

class SubmapMatcher {
 public:
  /// Throws std::invalid_argument for invalid options.
  explicit SubmapMatcher(const SubmapMatcherOptions& options = {});

  /// Matches b into a. Rejects (accepted = false, rejection set) for an
  /// unsuitable submap and any failed step. Throws std::invalid_argument if
  /// the prior has a non-finite entry, or the two submaps were built with
  /// different descriptor lengths.
  SubmapMatchResult Match(const SubmapMatchData& a, const SubmapMatchData& b,
                          const MatchPrior& prior) const;

  const SubmapMatcherOptions& options() const { return options_; }

 private:
  SubmapMatcherOptions options_;
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_LOOP_SUBMAP_MATCHER_H_
