#ifndef ROVER_MAPPING_LOOP_SUBMAP_PAIRING_H_
#define ROVER_MAPPING_LOOP_SUBMAP_PAIRING_H_

// Which pairs of submaps to match, in which order (thesis section 6.1.1).
// Finished submaps are added with their obstacle xy box and suitability; the
// graph's origin estimates T_world_origin and marginal covariances ([dp
// (world); dtheta (right)], RoverGraph::OriginCovariance) are updated as
// they change. A pair (a, b) is a candidate if
//   - both are suitable, they are not the same submap nor successive
//     submaps of one robot, and the pair is not done;
//   - the overlap of their obstacle boxes in the world, each axis enlarged by
//     k relative standard deviations (eq. 6.1, k = overlap_sigma_factor;
//     thesis k = 2), multiplied over x and y (eq. 6.2), exceeds
//     min_overlap_m2 (2 m^2);
//   - their mean relative standard deviation over x, y, z is not below the
//     matcher's precision, the stereo error at view_distance_m (eq. 6.3):
//     a match could not improve on the graph.
// Candidates are ranked by eq. 6.4, alpha * overlap' + sum of the relative
// sigmas (alpha = 0.125), best first.
//
// The relative uncertainty: the caller may set the exact one of a pair
// (SetRelativeCovariance, e.g. from the graph's joint marginals); otherwise
// it is approximated per axis from the two marginals: for one robot, as the
// thesis does, sqrt(|var_a - var_b|) (later origins carry the earlier ones'
// uncertainty plus the drift in between); for two robots, whose estimates
// are independent until a first inter-robot loop closure,
// sqrt(var_a + var_b).
//
// A pair is handed out by Next() once and never again; MarkDone() records a
// pair tried elsewhere (another robot's matcher). Not thread-safe: the
// caller (mapd's loop-closure thread) owns it; everything it returns is a
// value.

#include <map>
#include <optional>
#include <queue>
#include <set>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/config/config.h"
#include "mapping/graph/pose_graph.h"
#include "mapping/loop/submap_id.h"
#include "mapping/loop/submap_match_data.h"
#include "mapping/loop/submap_matcher.h"

namespace rover::mapping {

struct SubmapPairingOptions {
  /// Eq. 6.2 threshold.
  double min_overlap_m2 = 2.0;
  /// k of eq. 6.1 (thesis: 2); also the k-sigma of the pair's prior bounds
  /// if the matcher uses it.
  double overlap_sigma_factor = 3.0;
  /// Eq. 6.4 weight.
  double alpha = 0.125;
  /// Eq. 6.3, the matcher's precision dp * z^2 / (f b) * sqrt(2): defaults
  /// are the simulator's head (f = 460 px, b = 0.11 m) at the thesis's 4 m
  /// and 0.5 px; 0 disables the check.
  double pixel_error_px = 0.5;
  double focal_px = 460.0;
  double baseline_m = 0.11;
  double view_distance_m = 4.0;
  /// Successive submaps of one robot are never paired (thesis).
  bool skip_successive = true;

  /// Throws std::invalid_argument "SubmapPairingOptions.<key>: ...".
  void Validate() const;
  /// Keys as the fields; a key the node does not name keeps its value in
  /// `defaults`.
  static SubmapPairingOptions Load(const ConfigNode& node, const SubmapPairingOptions& defaults);
  /// As above, over the library's defaults.
  static SubmapPairingOptions Load(const ConfigNode& node);

  /// The right-hand side of eq. 6.3.
  double MatcherPrecisionM() const;
};

/// Why a pair is, or is not, a candidate (the first rule it fails).
enum class PairVerdict {
  kCandidate,
  kSameSubmap,
  kUnsuitable,            ///< one of the two submaps is unsuitable for matching
  kSuccessive,            ///< successive submaps of one robot
  kDone,                  ///< handed out (matched) or marked done before
  kSmallOverlap,          ///< eq. 6.2: overlap' not above min_overlap_m2
  kBelowMatcherPrecision  ///< eq. 6.3: the graph already knows the pair better
};

/// Eq. 6.1 / 6.2: the product over x and y of the overlap of two submaps'
/// obstacle boxes (submap frames) placed in the world, each axis's overlap
/// enlarged by `enlarge_m` and floored at 0; 0 if either box is empty.
double ObstacleBoxOverlapM2(const Eigen::AlignedBox2d& box_a, const Eigen::Isometry3d& T_world_a,
                            const Eigen::AlignedBox2d& box_b, const Eigen::Isometry3d& T_world_b,
                            const Eigen::Vector2d& enlarge_m = Eigen::Vector2d::Zero());

/// "candidate", "unsuitable submap", ... for reports.
const char* PairVerdictName(PairVerdict verdict);

/// A pair to match, with the prior the matcher should use.
struct SubmapPair {
  SubmapId a;
  SubmapId b;
  double score = 0.0;
  /// overlap'_xy of eq. 6.2.
  double overlap_m2 = 0.0;
  /// Relative standard deviations in x, y, z (world axes).
  Eigen::Vector3d relative_sigma_m = Eigen::Vector3d::Zero();
  /// T_a_b from the origin estimates, covariance in frame a.
  MatchPrior prior;
};

class SubmapPairing {
 public:
  /// Throws std::invalid_argument for invalid options.
  explicit SubmapPairing(const SubmapPairingOptions& options = {});

  /// A finished submap with its current origin estimate. Unsuitable
  /// submaps are kept (and counted) but never paired. Throws
  /// std::invalid_argument if `id` was added before or the pose or
  /// covariance is not finite.
  void AddSubmap(const SubmapId& id, const SubmapMatchData& data,
                 const Eigen::Isometry3d& T_world_origin, const Matrix6d& covariance);

  /// Same, from the parts the pairing uses (tests, remote submaps).
  void AddSubmap(const SubmapId& id, bool suitable, const Eigen::AlignedBox2d& obstacle_box_xy,
                 const Eigen::Isometry3d& T_world_origin, const Matrix6d& covariance);

  /// New estimate of an origin (after a graph optimisation). Throws
  /// std::invalid_argument for an unknown id or non-finite input.
  void UpdateOrigin(const SubmapId& id, const Eigen::Isometry3d& T_world_origin,
                    const Matrix6d& covariance);

  /// The relative covariance of T_a_b over [dp (frame a); dtheta (right)],
  /// when the caller can compute it; used instead of the approximation
  /// until the next UpdateOrigin of a or b (for the pair (b, a) it is
  /// propagated to T_b_a to first order). Throws as UpdateOrigin.
  void SetRelativeCovariance(const SubmapId& a, const SubmapId& b, const Matrix6d& covariance);

  /// Records that the pair was matched (here or elsewhere): never handed out.
  void MarkDone(const SubmapId& a, const SubmapId& b);
  bool IsDone(const SubmapId& a, const SubmapId& b) const;

  /// The best candidate, marked done; nullopt if there is none.
  std::optional<SubmapPair> Next();

  /// All current candidates, best first (nothing is marked done).
  std::vector<SubmapPair> Candidates() const;

  /// The pair as the pairing sees it now, whether or not it is a candidate
  /// (for diagnostics and tests). Throws for an unknown id.
  SubmapPair Evaluate(const SubmapId& a, const SubmapId& b) const;

  /// Whether (a, b) is a candidate now and, if not, the first rule it
  /// fails; fills `pair` (when given) as Evaluate does once the pair gets
  /// as far as the overlap rule. Throws for an unknown id.
  PairVerdict Check(const SubmapId& a, const SubmapId& b, SubmapPair* pair = nullptr) const;

  int submap_count() const { return static_cast<int>(submaps_.size()); }
  int suitable_count() const;

 private:
  struct Entry {
    bool suitable = false;
    Eigen::AlignedBox2d box_xy;
    Eigen::Isometry3d T_world_origin = Eigen::Isometry3d::Identity();
    Matrix6d covariance = Matrix6d::Zero();
  };
  using Key = std::pair<SubmapId, SubmapId>;
  /// A caller's relative covariance, of T_frame_other.
  struct Relative {
    SubmapId frame;
    Matrix6d covariance;
  };
  /// Orders a priority queue best score first.
  struct WorseScore {
    bool operator()(const SubmapPair& x, const SubmapPair& y) const;
  };
  static Key Ordered(const SubmapId& a, const SubmapId& b);
  const Entry& Find(const SubmapId& id, const char* caller) const;

  SubmapPairingOptions options_;
  std::map<SubmapId, Entry> submaps_;
  std::map<Key, Relative> relative_;
  std::set<Key> done_;
  /// Candidates, rebuilt by Next() after any change.
  std::priority_queue<SubmapPair, std::vector<SubmapPair>, WorseScore> queue_;
  bool dirty_ = true;
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_LOOP_SUBMAP_PAIRING_H_
