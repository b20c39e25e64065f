#ifndef ROVER_FIRMWARE_MAPD_MAPD_H_
#define ROVER_FIRMWARE_MAPD_MAPD_H_

// mapd: the mapping process (DESIGN.md). It runs at normal priority and may
// be slow or crash without touching roverd. It subscribes to roverd's
// estimates, stereo pairs and frame switches, decides when a new submap
// starts (SubmapTrigger) and asks roverd for the frame switch that gives the
// submap its origin.
//
// Each submap records its origin (the switch record, graph factor w), the
// estimates and frames it received and the distance driven. With mapping on
// (and roverd's stereo calibration received), every stereo pair is placed
// at its capture time between the estimates around it and mapped by the
// LocalMapper (depth, obstacle classification, octree and cloud) into the
// submap of its frame; finished submaps go to mapd's own log and into the
// composed global map, written out when mapd stops.
//
// A (re)started mapd has lost whatever submap it was building, so its first
// act is to request a switch (reason "restart"): it resumes with a new
// submap.

#include <cstdint>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/ipc/transport.h"
#include "core/link/link_endpoint.h"
#include "core/time/time.h"
#include "firmware/mapd/local_mapper.h"
#include "firmware/mapd/loop_closer.h"
#include "firmware/mapd/pose_history.h"
#include "firmware/mapd/slam_worker.h"
#include "firmware/mapd/submap_trigger.h"
#include "firmware/mapd/tag_worker.h"
#include "firmware/mapd/team_exchange.h"
#include "firmware/runtime/health/process_memory.h"
#include "firmware/runtime/topics/rover_topics.h"
#include "mapping/slam/frame_switch_noise.h"
#include "mapping/slam/graph_log.h"
#include "mapping/submap/submap.h"
#include "mapping/submap/submap_options.h"
#include "mapping/tags/tag_ambiguity_resolver.h"

namespace rover::mapd {

class SubmapArchive;

struct MapdOptions {
  SubmapTriggerOptions trigger;
  /// Wall time between status messages when nothing changes.
  Duration status_period = Duration::Seconds(1);
  /// Subscriber queue for the estimates (400 Hz: about 0.6 s).
  uint64_t pose_queue = 256;

  /// Map the stereo pairs (depth, terrain, submap voxels and clouds). Off:
  /// only the submap bookkeeping above.
  bool mapping = true;
  LocalMapperOptions local_mapper{};
  mapping::SubmapOptions submap{};
  /// At most this many pairs per second of capture time are mapped (0: all
  /// that mapd keeps up with); the rest are skipped, newest first.
  double max_mapping_rate_hz = 2.0;
  /// Estimates kept to place pairs in time (400 Hz: 10 s).
  std::size_t pose_history = 4096;
  /// mapd's log is output_stem + ".mcap" (submaps, traversability), and the
  /// global map is exported to output_stem + ".bt", ".ot" and ".ply" when
  /// mapd stops; empty: nothing is written.
  std::string output_stem{};
  /// Robot name in frame ids (local/<robot>/<frame>).
  std::string robot_name = "rover";
  /// Capture time between traversability grids in the log.
  Duration traversability_period = Duration::Seconds(1);

  /// Run the pose graph (prior, frame switches; its own thread) and compose
  /// the global map at its optimised origins.
  bool slam = true;
  /// The graph's online settings (RoverGraphOptions::Online: one
  /// Gauss-Newton step per update, the rest in idle time).
  mapping::RoverGraphOptions graph = mapping::RoverGraphOptions::Online();
  /// The frame switches' covariances in the graph: the filter's plus an
  /// odometry error per metre driven (mapping/slam/frame_switch_noise.h).
  mapping::FrameSwitchNoiseOptions switch_noise{};
  /// This rover's id in the (team's) graph.
  int robot_id = 0;
  /// Wall time between global-pose updates handed to the graph thread.
  Duration global_pose_period = Duration::Milliseconds(200);
  /// Find loop closures by matching finished submaps (needs mapping and
  /// slam); accepted matches join the graph as c factors.
  bool loop_closures = true;
  LoopCloserOptions loop{};

  /// AprilTag detection on the mapped pairs' rectified left images (needs
  /// mapping); nullopt: off. A sighting of landmark markers joins the graph
  /// (with slam) as the filter's pose then (v) and one observation per tag
  /// (o); robot markers are logged and counted.
  std::optional<mapping::TagObserverOptions> tags{};
  /// Where the tag error tables are (mapping::TagErrorTableFileName); empty:
  /// beside mapd's log.
  std::string tag_tables_dir{};
  /// Build a missing or mismatched table there on the tag thread (seconds per
  /// table) instead of switching detection off. For the simulator, whose
  /// camera the tables cannot be made for ahead of time; a board has its
  /// tables from rover-tags lut.
  bool build_missing_tag_tables = false;
  /// The tag thread runs this much nicer than mapd.
  int tag_nice_increment = 5;
  /// Deciding ambiguous detections by the tag's other sightings.
  mapping::TagAmbiguityOptions tag_ambiguity{};

  /// Multi-robot SLAM (needs slam): this rover's graph factors go to the
  /// other rovers over the team link given to the constructor, and theirs
  /// join this rover's graph; the graph's robot id is robot_id.
  /// nullopt: alone.
  std::optional<TeamWorkerOptions> team{};
  /// In a team, estimates kept at this period for the other rovers'
  /// detections of this one, which may arrive minutes late (10 min).
  Duration team_pose_period = Duration::Milliseconds(100);
  std::size_t team_pose_history = 6000;

  /// Throws std::invalid_argument naming the key.
  void Validate() const;
};

/// One submap as mapd saw it.
struct SubmapRecord {
  uint32_t index = 0;     ///< 0, 1, ... within this mapd process
  uint32_t frame_id = 0;  ///< the filter's local frame it lives in
  /// The switch that started it (absent: mapd joined a frame already
  /// running and no switch has happened since).
  std::optional<runtime::topics::FrameSwitchMsg> origin;
  std::optional<runtime::topics::SwitchReason> reason;  ///< of the request that led to it
  Time first_stamp;
  Time last_stamp;
  uint64_t poses = 0;
  uint64_t frames = 0;
  double distance_m = 0.0;
};

/// Counters of one mapd process.
struct MapdStats {
  uint64_t poses = 0;
  uint64_t frames = 0;
  uint64_t frame_switches = 0;
  uint64_t requests = 0;
  uint64_t request_drops = 0;  ///< no transport buffer
  uint64_t missed = 0;         ///< queue overflows (mapd too slow: frames are expected to be)
  uint64_t version_mismatches = 0;
  // Mapping.
  uint64_t images_mapped = 0;
  uint64_t images_skipped = 0;    ///< over the mapping rate, or replaced while waiting
  uint64_t images_unplaced = 0;   ///< no estimate around the capture time, or a joined frame
  uint64_t images_failed = 0;     ///< the pipeline threw (bad size, ...)
  uint64_t submaps_archived = 0;  ///< finished, logged and composed
  uint64_t octree_bytes = 0;      ///< serialised octomap_msgs/Octomap of finished submaps
  uint64_t cloud_bytes = 0;       ///< serialised sensor_msgs/PointCloud2 of finished submaps
  uint64_t obstacle_points = 0;
  uint64_t grids_published = 0;
  uint64_t graph_states_published = 0;  ///< origin updates that went out whole
  uint64_t graph_publish_drops = 0;     ///< global poses not published (no chunk)
  uint64_t graph_factors_refused = 0;   ///< malformed before reaching the graph (NaN, ...)
  uint64_t graph_factors_resumed = 0;   ///< taken over from the previous mapd's log
  uint64_t loop_closures = 0;           ///< accepted matches added to the graph
  uint64_t inter_robot_closures = 0;    ///< of those, with another rover's submap
  // AprilTags (the tag thread's own counts are in tag_stats()).
  uint64_t tag_observations_logged = 0;
  uint64_t tag_sightings = 0;           ///< pose nodes (v) of images with landmark tags
  uint64_t tag_sightings_unplaced = 0;  ///< landmark tags whose frame was not in the graph
  uint64_t tag_factors = 0;             ///< o factors added
  uint64_t tags_resolved = 0;           ///< ambiguous, decided by the tag's other sightings
  uint64_t tags_inflated = 0;           ///< ambiguous, undecided: kept with the rotation left open
  uint64_t tags_unresolved = 0;         ///< ambiguous, and refused in the end (fit neither)
  uint64_t robot_tags_seen = 0;         ///< accepted robot markers (logged)
  uint64_t robot_detections = 0;        ///< d factors added (in a team)
  uint64_t robot_detections_unplaced = 0;  ///< this rover's frame was not in the graph
  uint64_t detected_poses = 0;  ///< other rovers' detections of this one linked (v added)
  uint64_t detected_poses_unplaced =
      0;  ///< no estimate of then kept, or its frame not in the graph
  double mapping_ms_total = 0.0;
  /// First and last stereo pair seen (any), for the raw stereo byte rate.
  std::optional<uint64_t> first_sequence;
  uint64_t last_sequence = 0;
  int64_t first_capture_ns = 0;
  int64_t last_capture_ns = 0;
  uint64_t pair_bytes = 0;  ///< bytes of one raw pair (two mono8 images)
};

/// Per-second byte rates of a run (thesis: 38.75 MB/s raw stereo against
/// about 58 KB/s as submaps).
struct MapdBandwidth {
  double raw_stereo_bytes_per_s = 0.0;
  double submap_bytes_per_s = 0.0;
};

class Mapd {
 public:
  /// Creates the endpoints on `transport`. With options.team, `team_link` is
  /// this rover's end of the team link (robot options.robot_id); the team
  /// thread starts once mapd knows whether it resumes an earlier log. Throws
  /// std::runtime_error naming a topic the transport refused,
  /// std::invalid_argument for bad options or a team without a link.
  Mapd(const MapdOptions& options, ipc::Transport* transport,
       std::unique_ptr<link::LinkEndpoint> team_link = nullptr);
  ~Mapd();
  Mapd(const Mapd&) = delete;
  Mapd& operator=(const Mapd&) = delete;

  /// Takes everything queued and acts on it; returns the number of messages
  /// handled (0: nothing new; the caller may sleep).
  int Poll();

  const std::vector<SubmapRecord>& submaps() const { return submaps_; }
  const MapdStats& stats() const { return stats_; }
  /// The pose graph's counters (empty without slam).
  SlamStats slam_stats() const { return slam_ ? slam_->Stats() : SlamStats{}; }
  /// The loop closer's counters (empty without loop closures).
  LoopCloserStats loop_stats() const { return loop_ ? loop_->Stats() : LoopCloserStats{}; }
  /// The tag thread's counters (empty with tags off).
  TagWorkerStats tag_stats() const { return tags_ ? tags_->Stats() : TagWorkerStats{}; }
  /// The team exchange's counters (empty alone or before it started).
  TeamExchangeStats team_stats() const { return team_ ? team_->Stats() : TeamExchangeStats{}; }
  /// The latest graph snapshot (update 0 without slam).
  SlamSnapshot slam_snapshot() const { return slam_ ? slam_->Latest() : SlamSnapshot{}; }

  /// Finishes the current submap, writes the run's statistics, the global
  /// map (map.bt, map.ot, map.ply) and closes the log. Idempotent; the
  /// destructor calls it.
  void Shutdown();

  /// Byte rates over the capture time seen so far.
  MapdBandwidth Bandwidth() const;

  /// Human-readable summary for the end of a run.
  std::string Summary() const;

  /// Path of mapd's log (empty: none).
  std::string log_path() const;

 private:
  void OnPose(const runtime::topics::PoseMsg& pose);
  void OnFrameSwitch(const runtime::topics::FrameSwitchMsg& record);
  void OnFrame(const runtime::topics::StereoFrameMsg& frame);
  /// The record of `frame_id`'s submap, opened if this process saw the frame
  /// begin; nullptr for a frame joined half-way.
  SubmapRecord* Current(uint32_t frame_id, Time stamp);
  void PublishStatus();
  void TakeCalibration();
  /// Maps the pending pair once the estimates around it have arrived.
  void TryMapPending();
  void MapPair(const runtime::topics::StereoFrameMsg& frame, const StampedPose& pose);
  /// Archives the mapping submap (log, composition) and forgets it.
  void FinishMappingSubmap();
  void LogTraversability(int64_t stamp_ns);
  /// Logs `factor` (with the next id), hands its logged form to the graph
  /// and shares it with the team.
  void AddFactor(mapping::GraphFactorRecord factor);
  void LogAndSubmit(const log::rover_msgs::GraphFactor& msg);
  /// Reads the graph of the newest earlier mapd log beside ours.
  void LoadResumeCandidate();
  /// Once, at the first switch record or estimate: carries on with the
  /// earlier log's graph if roverd's switch history shows it is this
  /// mission's (a restart), or starts a new one.
  void DecideResume(const runtime::topics::FrameSwitchMsg* record);
  /// Starts the team exchange (with options.team) once the resume is
  /// decided: a resumed log's team messages are what this rover already has.
  void StartTeam(const mapping::GraphLogContents* resumed);
  /// Takes what the team sent: constraints into the graph, claims and
  /// submaps to the loop closer.
  void TakeTeam();
  /// Anchors the graph at `frame_id` (once): the world frame of this rover.
  void EnsurePrior(uint32_t frame_id, int64_t stamp_ns);
  /// Takes a new graph snapshot: moves the composed submaps, logs it.
  void TakeSlamSnapshot();
  /// Hands the newest estimate to the graph thread for the global pose.
  void HandLatestPose();
  /// Publishes the snapshot's origins (in pages), and its global pose.
  void PublishOrigins(const SlamSnapshot& snap);
  void PublishGlobalPose(const SlamSnapshot& snap);
  /// Logs the snapshot's origins (and moves the composed submaps), and its
  /// global pose.
  void LogOrigins(const SlamSnapshot& snap);
  void LogGlobalPose(const SlamSnapshot& snap);
  /// Adds the loop closer's accepted matches to the graph.
  void TakeLoopMatches();
  /// Starts the tag thread once the rectified camera is known.
  void StartTags();
  /// Logs the tag thread's observations and adds the landmark sightings'
  /// factors.
  void TakeTagResults();
  /// Logs one observation, or keeps an ambiguous one until the resolver
  /// decides it; accepted landmark tags join the graph.
  void HandleTagObservation(const TagSighting& sighting, mapping::TagObservation observation);
  /// Applies the resolver's decisions to the waiting observations.
  void ApplyTagDecisions(const std::vector<mapping::TagDecision>& decisions);
  void LogTag(const TagSighting& sighting, const mapping::TagObservation& observation);
  /// The sighting's pose (v, once per image) and the tag's o factor.
  void AddTagFactor(const TagSighting& sighting, const mapping::TagObservation& observation);
  /// This rover's pose node at the sighting's instant (its v factor, once);
  /// nullopt if the sighting's frame is not in the graph.
  std::optional<int64_t> EnsurePoseNode(const TagSighting& sighting);
  /// A team mate's marker seen: this rover's pose node and the d factor to
  /// the other rover's pose at the same instant.
  void AddRobotDetection(const TagSighting& sighting, const mapping::TagObservation& observation);
  /// Another rover saw this one (`detection` names this rover's pose): adds
  /// this rover's estimate of then as that pose's v factor.
  void AddDetectedPose(const mapping::GraphFactorRecord& detection);
  /// Detections of this rover newer than its newest estimate wait for the
  /// estimates of their instant; `final`: the last try (end of the run).
  void RetryWaitingDetections(bool final);
  /// True if local frame `frame_id`'s origin is in the graph (the prior's
  /// frame, or one a frame switch led to).
  bool FrameInGraph(uint32_t frame_id) const;
  /// Logs what mapd's memory is made of (a "mapd: memory" status on
  /// /diagnostics), after a finished submap.
  void LogMemory(int64_t stamp_ns);

  MapdOptions options_;
  SubmapTrigger trigger_;
  std::unique_ptr<ipc::Subscriber<runtime::topics::PoseMsg>> poses_;
  std::unique_ptr<ipc::Subscriber<runtime::topics::StereoFrameMsg>> frames_;
  std::unique_ptr<ipc::Subscriber<runtime::topics::FrameSwitchMsg>> switches_;
  std::unique_ptr<ipc::Publisher<runtime::topics::FrameSwitchRequestMsg>> requests_;
  std::unique_ptr<ipc::Publisher<runtime::topics::MapdStatusMsg>> status_;
  std::unique_ptr<ipc::Subscriber<runtime::topics::StereoCalibrationMsg>> calibration_;
  std::unique_ptr<ipc::Publisher<runtime::topics::TraversabilityMsg>> traversability_;
  std::unique_ptr<ipc::Publisher<runtime::topics::GlobalPoseMsg>> global_pose_;
  std::unique_ptr<ipc::Publisher<runtime::topics::SubmapOriginsMsg>> origins_;
  /// 2 MB: one frame buffer, allocated once.
  std::unique_ptr<runtime::topics::StereoFrameMsg> frame_buffer_;
  /// The newest pair waiting for its estimates (mapping only).
  std::unique_ptr<runtime::topics::StereoFrameMsg> pending_frame_;
  bool has_pending_ = false;
  PoseHistory history_;
  PoseHistory team_history_;  ///< decimated, for late detections by team mates
  int64_t last_team_history_ns_ = 0;
  /// Other rovers' detections of this one from its future (the clocks of a
  /// lockstep simulation differ, a real one's estimates lag).
  std::vector<mapping::GraphFactorRecord> waiting_detections_;
  static constexpr std::size_t kMaxWaitingDetections = 4096;
  std::unique_ptr<LocalMapper> mapper_;
  std::unique_ptr<mapping::Submap> mapping_submap_;
  std::unique_ptr<SubmapArchive> archive_;
  std::optional<Time> last_mapped_capture_;
  std::optional<Time> last_traversability_;
  std::unique_ptr<SlamWorker> slam_;
  std::unique_ptr<LoopCloser> loop_;
  std::unique_ptr<TagWorker> tags_;
  std::set<int> unknown_tag_ids_;  ///< reported once each
  mapping::TagAmbiguityResolver tag_resolver_;
  std::unique_ptr<link::LinkEndpoint> team_link_;  ///< until the team starts
  std::unique_ptr<TeamExchange> team_;
  int64_t newest_stamp_ns_ = 0;  ///< of any estimate: the team messages' log time
  /// Ambiguous observations waiting for the resolver, by key.
  std::map<uint64_t, std::pair<TagSighting, mapping::TagObservation>> waiting_tags_;
  uint64_t next_tag_key_ = 1;
  std::set<int64_t> tag_pose_nodes_;  ///< pose keys with their v factor
  int64_t newest_tag_stamp_ns_ = 0;
  bool prior_added_ = false;
  std::optional<int64_t> prior_frame_;
  uint64_t next_factor_id_ = 1;
  uint64_t last_snapshot_update_ = 0;
  uint64_t last_origins_update_ = 0;
  Time last_global_pose_handed_;
  std::optional<runtime::topics::PoseMsg> latest_pose_;  ///< not yet handed over
  std::optional<mapping::GraphLogContents> resume_candidate_;
  std::string resume_path_;
  bool resume_decided_ = false;
  std::set<int64_t> switched_frames_;  ///< frames whose switch (w) the graph has
  bool shut_down_ = false;
  std::vector<SubmapRecord> submaps_;
  std::optional<runtime::topics::FrameSwitchMsg> pending_origin_;
  std::optional<runtime::topics::SwitchReason> last_reason_;  ///< of the request out
  std::optional<uint32_t> request_frame_;  ///< the frame that request was made in
  MapdStats stats_;
  /// Memory after the first and the latest finished submap.
  std::optional<runtime::ProcessMemory> first_memory_;
  std::optional<runtime::ProcessMemory> last_memory_;
  bool memory_error_reported_ = false;
  uint64_t next_request_id_ = 1;
  Time last_status_wall_;
};

}  // namespace rover::mapd

#endif  // ROVER_FIRMWARE_MAPD_MAPD_H_
