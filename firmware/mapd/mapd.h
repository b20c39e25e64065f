#ifndef ROVER_FIRMWARE_MAPD_MAPD_H_
#define ROVER_FIRMWARE_MAPD_MAPD_H_

// mapd: the mapping process (DESIGN.md). It runs at normal priority and may
// be slow or crash without touching roverd. It subscribes to roverd's
// estimates, stereo pairs and frame switches, decides when a new submap
// starts (SubmapTrigger) and asks roverd for the frame switch that gives the
// submap its origin.
//
// This is the skeleton and the data flow: each submap records its origin
// (the switch record, graph factor w), the estimates and frames it received
// and the distance driven. Depth, terrain classification, the submap's
// voxels and the pose graph plug in here (mapping/).
//
// A (re)started mapd has lost whatever submap it was building, so its first
// act is to request a switch (reason "restart"): it resumes with a new
// submap.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/ipc/transport.h"
#include "core/time/time.h"
#include "firmware/mapd/submap_trigger.h"
#include "firmware/runtime/topics/rover_topics.h"

namespace rover::mapd {

struct MapdOptions {
  SubmapTriggerOptions trigger;
  /// Wall time between status messages when nothing changes.
  Duration status_period = Duration::Seconds(1);
  /// Subscriber queue for the estimates (400 Hz: about 0.6 s).
  uint64_t pose_queue = 256;
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
};

class Mapd {
 public:
  /// Creates the endpoints on `transport`. Throws std::runtime_error naming a
  /// topic the transport refused, std::invalid_argument for bad options.
  Mapd(const MapdOptions& options, ipc::Transport* transport);
  ~Mapd();
  Mapd(const Mapd&) = delete;
  Mapd& operator=(const Mapd&) = delete;

  /// Takes everything queued and acts on it; returns the number of messages
  /// handled (0: nothing new; the caller may sleep).
  int Poll();

  const std::vector<SubmapRecord>& submaps() const { return submaps_; }
  const MapdStats& stats() const { return stats_; }

  /// Human-readable summary for the end of a run.
  std::string Summary() const;

 private:
  void OnPose(const runtime::topics::PoseMsg& pose);
  void OnFrameSwitch(const runtime::topics::FrameSwitchMsg& record);
  void OnFrame(const runtime::topics::StereoFrameMsg& frame);
  /// The record of `frame_id`'s submap, opened if this process saw the frame
  /// begin; nullptr for a frame joined half-way.
  SubmapRecord* Current(uint32_t frame_id, Time stamp);
  void PublishStatus();

  MapdOptions options_;
  SubmapTrigger trigger_;
  std::unique_ptr<ipc::Subscriber<runtime::topics::PoseMsg>> poses_;
  std::unique_ptr<ipc::Subscriber<runtime::topics::StereoFrameMsg>> frames_;
  std::unique_ptr<ipc::Subscriber<runtime::topics::FrameSwitchMsg>> switches_;
  std::unique_ptr<ipc::Publisher<runtime::topics::FrameSwitchRequestMsg>> requests_;
  std::unique_ptr<ipc::Publisher<runtime::topics::MapdStatusMsg>> status_;
  /// 2 MB: one frame buffer, allocated once.
  std::unique_ptr<runtime::topics::StereoFrameMsg> frame_buffer_;
  std::vector<SubmapRecord> submaps_;
  std::optional<runtime::topics::FrameSwitchMsg> pending_origin_;
  std::optional<runtime::topics::SwitchReason> last_reason_;  ///< of the request out
  std::optional<uint32_t> request_frame_;  ///< the frame that request was made in
  MapdStats stats_;
  uint64_t next_request_id_ = 1;
  Time last_status_wall_;
};

}  // namespace rover::mapd

#endif  // ROVER_FIRMWARE_MAPD_MAPD_H_
