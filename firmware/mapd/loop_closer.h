#ifndef ROVER_FIRMWARE_MAPD_LOOP_CLOSER_H_
#define ROVER_FIRMWARE_MAPD_LOOP_CLOSER_H_

// mapd's loop closures by submap matching (thesis 6.1), in two threads
// below mapd's normal priority:
//   pairing   takes each finished submap, computes its matching data once
//             (keypoints, descriptors, k-d trees; SubmapMatchData), adds it
//             to the SubmapPairing with the graph's current origin estimate,
//             follows the graph's updates, and hands the best candidate
//             pairs to the matcher, each pair once;
//   matching  runs the 4D matcher (or the 6D baseline) on one pair at a time.
// mapd's main loop takes the results (TakeMatches) and adds the accepted
// ones to the pose graph as c factors; loop closures never reach the filter.
// A submap's matching data outlives the submap itself (mapd drops the
// octree once it is archived) and stays for the whole mission, as any later
// submap may pair with it: in a MatchDataStore, which keeps the recently
// used in memory and spills the rest to disk, so that memory stays flat on
// a long mission. The data of a submap the pairing refused as unsuitable is
// dropped at once.
//
// In a team, the other rovers' submaps (from the team link) join the pairing
// at the graph's estimate of their origins. A pair of this rover's submap
// and another rover's is matched here unless that rover announced it first
// (a claim); a pair of two other rovers' submaps is theirs. Every match is
// reported with this rover's submap as `a`, so the factor is this rover's.

#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "core/config/config.h"
#include "firmware/mapd/slam_worker.h"
#include "mapping/loop/match_data_store.h"
#include "mapping/loop/submap_id.h"
#include "mapping/loop/submap_match_data.h"
#include "mapping/loop/submap_matcher.h"
#include "mapping/loop/submap_pairing.h"
#include "mapping/submap/submap.h"

namespace rover::mapd {

struct LoopCloserOptions {
  mapping::SubmapMatchDataOptions data{};
  /// The library's defaults but for eq. 6.3's gate: the thesis's 0.5 px at
  /// 4 m predicts a matcher precision of 0.22 m on the simulator's head,
  /// while the 4D matcher's accepted matches are within 0.02 m (median,
  /// rover-sim loop on mixed-300m); with the thesis's figure the gate refused
  /// every pair of a 300 m drive (relative sigmas 0.03-0.1 m). 1.5 m gives
  /// 0.03 m.
  mapping::SubmapPairingOptions pairing = [] {
    mapping::SubmapPairingOptions o;
    o.view_distance_m = 1.5;
    return o;
  }();
  /// The library's defaults but for
  ///   - the prior's smallest search bounds: the origins' covariances come
  ///     from the filter's switch covariances, which understated the drift
  ///     (mixed-300m seed 1: origin sigmas 0.05-0.1 m against 0.46 m final
  ///     error), so the bounds must not shrink below what the drift can be;
  ///   - the yaw innovation gate, at 3 of the prior's sigmas: on a 1 km
  ///     figure-eight it refused the two matches more than 1 deg off the
  ///     truth and two valid ones 0.4 and 0.9 deg off, where the graph knew
  ///     the relative heading to 0.15-0.26 deg (precision 0.91 -> 1.00);
  ///     mixed-300m's closures come well inside it;
  ///   - an ICP that leaves out what only one side saw well: Cauchy weights
  ///     annealed down to 3 cm and normals within 30 deg. Two submaps that
  ///     saw the rocks from opposite sides have surfaces (flanks, stereo
  ///     fringes) that pull plain least squares towards each camera: every
  ///     run showed a common offset of -3 cm along the heading, though the
  ///     submaps' content sits within 2 mm of the true terrain
  ///     (EstimateContentShift). Replayed on the same logs (mixed-300m
  ///     seeds 2, 3, 5 and the figure-eight), the median match error went
  ///     from 0.060 m / 0.24 deg to 0.032 m / 0.07 deg on the figure-eight,
  ///     valid matches from 21 to 34 of about 100 pairs, invalid ones from
  ///     1 to 0; monotonous-200m still accepts none.
  mapping::SubmapMatcherOptions matcher = [] {
    mapping::SubmapMatcherOptions o;
    o.min_bound_m = 1.0;
    o.min_bound_yaw_rad = 5.0 * M_PI / 180.0;
    o.max_yaw_innovation_sigmas = 3.0;
    o.icp.robust_scale_m = 0.03;
    o.icp.max_normal_angle_deg = 30.0;
    return o;
  }();
  /// Pairs waiting for the matching thread at most; the pairing hands out
  /// the next best pair only once the queue has room, so a graph update in
  /// between can still reorder (or drop) the candidates.
  int max_queued_pairs = 2;
  /// Nice increment of both threads over mapd's main loop.
  int nice_increment = 10;
  /// Where the match data live (memory bound, spill directory).
  mapping::MatchDataStoreOptions store{};

  /// Throws std::invalid_argument naming the key.
  void Validate() const;
  /// Keys: data, pairing, matcher (child maps, as their Load), store
  /// (resident_submaps, spill_directory) and the fields above (all
  /// optional).
  static LoopCloserOptions Load(const ConfigNode& node);
};

/// One matched pair, accepted or not.
struct LoopMatch {
  mapping::SubmapId a;
  mapping::SubmapId b;
  /// The prior the pairing gave (T_a_b from the origin estimates).
  mapping::MatchPrior prior;
  bool accepted = false;
  std::string rejection;  ///< empty when accepted
  Eigen::Isometry3d T_a_b = Eigen::Isometry3d::Identity();
  mapping::Matrix6d covariance = mapping::Matrix6d::Identity();
  int inliers = 0;
  /// No keypoint hypothesis: the ICP started from the tight prior.
  bool from_prior = false;
  double rmse_m = 0.0;
  double match_ms = 0.0;
};

/// Counters so far.
struct LoopCloserStats {
  uint64_t submaps = 0;           ///< handed over
  uint64_t submaps_suitable = 0;  ///< whose matching data passed the suitability checks
  uint64_t submaps_failed = 0;    ///< matching data could not be computed (message in problems)
  uint64_t pairs_matched = 0;
  uint64_t matches_accepted = 0;
  uint64_t team_submaps = 0;        ///< other rovers' submaps handed over
  uint64_t team_pairs_matched = 0;  ///< of pairs_matched, with another rover's submap
  uint64_t team_matches_accepted = 0;
  uint64_t pairs_claimed_by_others = 0;  ///< left to the rover that announced them
  std::vector<double> data_ms;           ///< per submap
  std::vector<double> match_ms;          ///< per matched pair
  mapping::MatchDataStoreStats store;
};

class LoopCloser {
 public:
  /// Starts both threads; `robot` is this rover's id (SubmapId::robot).
  /// Throws std::invalid_argument for invalid options.
  LoopCloser(const LoopCloserOptions& options, int robot);
  ~LoopCloser();
  LoopCloser(const LoopCloser&) = delete;
  LoopCloser& operator=(const LoopCloser&) = delete;

  /// Hands over a finished submap; its matching data is computed in the
  /// pairing thread, which keeps `submap` only until then.
  void AddSubmap(std::shared_ptr<const mapping::Submap> submap);
  /// Hands over another rover's finished submap `id` (from the team link).
  void AddTeamSubmap(const mapping::SubmapId& id, std::shared_ptr<const octomap::OcTree> octree,
                     std::shared_ptr<const mapping::PointCloud> cloud);
  /// The graph's origin estimates after an update: this robot's by local
  /// frame id, and the other rovers' the graph has placed. A submap joins
  /// the pairing once its origin is known.
  void UpdateOrigins(const std::map<int64_t, OptimisedOrigin>& origins,
                     const std::map<mapping::SubmapId, OptimisedOrigin>& team_origins = {});
  /// Robot `claimant` announced that it matches `a` with `b`: not matched
  /// here, and a match of that pair finished here is refused if the claimant
  /// has the lower id (the tie-break when both started at once).
  void AddClaim(const mapping::SubmapId& a, const mapping::SubmapId& b, int claimant);
  /// Pairs of this rover's submap and another rover's that this rover
  /// started to match since the last call, to announce to the team.
  std::vector<std::pair<mapping::SubmapId, mapping::SubmapId>> TakeClaims();
  /// Matches finished since the last call, in the order they finished.
  std::vector<LoopMatch> TakeMatches();
  /// Messages (submaps whose data failed) since the last call.
  std::vector<std::string> TakeProblems();
  LoopCloserStats Stats() const;
  /// Waits until every submap handed over has its data and every candidate
  /// pair the current origins give has been matched (tests, end of a run).
  void Flush();
  /// Stops both threads (idempotent; the destructor calls it).
  void Stop();

 private:
  struct Prepared {
    bool paired = false;      ///< tried to add to the pairing
    bool in_pairing = false;  ///< added
  };
  /// A submap waiting for its matching data: this rover's (`submap`) or
  /// another's (`octree` and `cloud`).
  struct Waiting {
    mapping::SubmapId id;
    std::shared_ptr<const mapping::Submap> submap;
    std::shared_ptr<const octomap::OcTree> octree;
    std::shared_ptr<const mapping::PointCloud> cloud;
  };
  using PairKey = std::pair<mapping::SubmapId, mapping::SubmapId>;  ///< ordered
  static PairKey KeyOf(const mapping::SubmapId& a, const mapping::SubmapId& b) {
    return a < b ? PairKey{a, b} : PairKey{b, a};
  }
  /// The match data store's key of a submap (robot in the high bits).
  static int64_t StoreKey(const mapping::SubmapId& id) {
    return (static_cast<int64_t>(id.robot) << 40) | id.index;
  }
  void RunPairing();
  void RunMatching();
  /// Pairing thread, lock held on entry and exit: computes the data of
  /// every waiting submap (unlocked while it works).
  void PrepareWaiting(std::unique_lock<std::mutex>* lock);
  /// Pairing thread, lock held: adds prepared submaps whose origin is now
  /// known, applies new origins.
  void SyncPairing();
  /// Pairing thread, lock held: moves candidates into the match queue.
  void QueuePairs();
  /// Lock held: the store's data for `frame`, null (and a problem noted) if
  /// it cannot be read back.
  std::shared_ptr<const mapping::SubmapMatchData> StoredData(const mapping::SubmapId& id);
  bool PairingIdle() const;

  const LoopCloserOptions options_;
  const int robot_;
  const mapping::SubmapMatcher matcher_;
  mutable std::mutex mutex_;
  std::condition_variable wake_pairing_;
  std::condition_variable wake_matching_;
  std::condition_variable idle_;
  std::deque<Waiting> waiting_;
  bool preparing_ = false;
  std::map<mapping::SubmapId, OptimisedOrigin> origins_;
  bool origins_changed_ = false;
  mapping::SubmapPairing pairing_;
  std::map<mapping::SubmapId, Prepared> prepared_;
  mapping::MatchDataStore store_;   ///< by StoreKey; suitable submaps only once paired
  std::map<PairKey, int> claimed_;  ///< pairs another rover announced, by the lowest claimant
  std::vector<PairKey> claims_out_;
  struct QueuedPair {
    mapping::SubmapPair pair;
    std::shared_ptr<const mapping::SubmapMatchData> a;
    std::shared_ptr<const mapping::SubmapMatchData> b;
  };
  std::deque<QueuedPair> queue_;
  bool matching_ = false;
  bool slot_freed_ = false;  ///< a match finished: the pairing may queue the next
  std::vector<LoopMatch> done_;
  std::vector<std::string> problems_;
  LoopCloserStats stats_;
  bool stop_ = false;
  std::thread pairing_thread_;  // last two: started once everything above exists
  std::thread matching_thread_;
};

}  // namespace rover::mapd

#endif  // ROVER_FIRMWARE_MAPD_LOOP_CLOSER_H_
