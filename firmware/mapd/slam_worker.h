#ifndef ROVER_FIRMWARE_MAPD_SLAM_WORKER_H_
#define ROVER_FIRMWARE_MAPD_SLAM_WORKER_H_

// mapd's pose-graph thread: owns the RoverGraph, takes the factors mapd's
// main loop hands it (each already logged), and after each batch updates the
// graph (a solve only when a factor closes a loop; see
// RoverGraph::Optimize) and publishes a snapshot: every origin T_world_frame
// with its marginal covariance and the current global pose s_j (+) v_t. It
// runs below mapd's normal priority: a slow solve delays the optimised map,
// never the mapping of stereo pairs. Loop closures never go back into the
// filter.

#include <Eigen/Geometry>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "mapping/graph/rover_graph.h"
#include "mapping/loop/submap_id.h"
#include "mapping/slam/graph_factor_record.h"

namespace rover::mapd {

/// One submap origin after an update.
struct OptimisedOrigin {
  Eigen::Isometry3d T_world_origin = Eigen::Isometry3d::Identity();
  mapping::Matrix6d covariance = mapping::Matrix6d::Zero();  ///< zero: not computed
};

/// The graph's state after one update.
struct SlamSnapshot {
  uint64_t update = 0;  ///< 0: no update yet
  /// The update that last changed the origins (a factor was added, or an
  /// idle-time step moved them); later updates only moved the global pose.
  uint64_t origins_update = 0;
  int64_t stamp_ns = 0;  ///< of the newest factor or pose it includes
  /// This rover's origins, by the filter's local frame id.
  std::map<int64_t, OptimisedOrigin> origins;
  /// In a team: the other rovers' origins that the graph has placed (linked
  /// to this rover's map), by robot and frame.
  std::map<mapping::SubmapId, OptimisedOrigin> team_origins;
  std::optional<Eigen::Isometry3d> T_world_body;  ///< s_j (+) v_t
  int64_t global_pose_stamp_ns = 0;
  uint32_t global_pose_frame_id = 0;
  mapping::Matrix6d global_pose_covariance = mapping::Matrix6d::Zero();
  mapping::RoverGraphSummary summary;
  double update_ms = 0.0;
};

/// Counters of the graph thread.
struct SlamStats {
  uint64_t factors_added = 0;
  uint64_t factors_refused = 0;  ///< NaN, not positive definite, keys that do not fit
  uint64_t updates = 0;
  uint64_t solves = 0;
  uint64_t update_errors = 0;     ///< Optimize threw (e.g. a disconnected robot)
  uint64_t refinements = 0;       ///< steps taken in idle time (RoverGraph::Refine)
  std::vector<double> update_ms;  ///< every update, for percentiles
};

class SlamWorker {
 public:
  /// Starts the thread. `robot` is this rover's id in the graph.
  SlamWorker(const mapping::RoverGraphOptions& options, int robot);
  ~SlamWorker();
  SlamWorker(const SlamWorker&) = delete;
  SlamWorker& operator=(const SlamWorker&) = delete;

  /// Hands over a factor (already logged); the next update adds it.
  void Submit(const mapping::GraphFactorRecord& factor);
  /// The filter's latest estimate in local frame `frame_id`, for the global
  /// pose (kept outside the graph); position covariance over [dp; dtheta].
  void SetFilterPose(int64_t stamp_ns, uint32_t frame_id, const Eigen::Isometry3d& T_local_body,
                     const mapping::Matrix6d& covariance);
  /// The latest snapshot (a copy).
  SlamSnapshot Latest() const;
  /// Counters so far (a copy).
  SlamStats Stats() const;
  /// Messages for refused factors and failed updates since the last call.
  std::vector<std::string> TakeProblems();
  /// Waits until every factor submitted so far is in an update and the
  /// idle-time steps after it are done (tests, end of a run).
  void Flush();
  /// Stops the thread (idempotent; the destructor calls it).
  void Stop();

 private:
  void Run();
  // Adds `batch` and optimises; with an empty batch and `refine`, takes one
  // more step of an unconverged update instead (RoverGraph::Refine).
  void UpdateOnce(std::deque<mapping::GraphFactorRecord>* batch, bool refine);

  const int robot_;
  mapping::RoverGraph graph_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable idle_;
  std::deque<mapping::GraphFactorRecord> inbox_;
  bool busy_ = false;
  bool stop_ = false;
  bool pose_changed_ = false;
  bool refining_ = false;  // the graph needs more steps (RoverGraph::NeedsRefinement)
  struct FilterPose {
    int64_t stamp_ns = 0;
    uint32_t frame_id = 0;
    Eigen::Isometry3d T_local_body = Eigen::Isometry3d::Identity();
    mapping::Matrix6d covariance = mapping::Matrix6d::Zero();
  };
  std::optional<FilterPose> filter_pose_;
  SlamSnapshot latest_;
  SlamStats stats_;
  std::vector<std::string> problems_;
  std::size_t unanchored_reported_ = 0;  // graph thread only
  std::thread thread_;                   // last: started once everything above exists
};

}  // namespace rover::mapd

#endif  // ROVER_FIRMWARE_MAPD_SLAM_WORKER_H_
