#ifndef ROVER_FIRMWARE_MAPD_SUBMAP_TRIGGER_H_
#define ROVER_FIRMWARE_MAPD_SUBMAP_TRIGGER_H_

// When mapd starts a new submap (thesis, local mapping): as soon as the
// filter's position uncertainty in the current local frame exceeds a bound
// (0.1 m), or the rover has driven a distance (7 m) in it. mapd then asks
// roverd for a frame switch; the switch record becomes the new submap's
// origin. Between the request and the switch (the next estimate carrying a
// new frame id) no second request is made, unless the switch does not come
// within `request_retry` (the request was lost, e.g. roverd restarted).

#include <Eigen/Core>

#include <cstdint>
#include <optional>

#include "core/config/config.h"
#include "core/time/time.h"
#include "firmware/runtime/topics/rover_topics.h"

namespace rover::mapd {

struct SubmapTriggerOptions {
  double max_distance_m = 7.0;
  double max_position_sigma_m = 0.1;
  /// Sensor time after which an unanswered request is repeated.
  Duration request_retry = Duration::Seconds(2);

  /// Throws std::invalid_argument "SubmapTriggerOptions.<key>: expected ...,
  /// found ..." for a non-positive or non-finite limit.
  void Validate() const;
};

class SubmapTrigger {
 public:
  explicit SubmapTrigger(const SubmapTriggerOptions& options);

  /// Feeds one estimate (in stamp order). Returns the reason for a frame
  /// switch request if one is due now.
  std::optional<runtime::topics::SwitchReason> OnPose(Time stamp, uint32_t frame_id,
                                                      const Eigen::Vector3d& p_local_body_m,
                                                      double position_sigma_m);

  /// Makes the next OnPose ask for a switch (reason kRestart), whatever the
  /// distance and uncertainty: a (re)started mapd has no submap to add to.
  void RequestAtNextPose() { pending_restart_ = true; }

  /// Distance driven in the current local frame since it began (or since
  /// this trigger first saw it).
  double distance_m() const { return distance_m_; }
  /// The local frame the last estimate was in.
  std::optional<uint32_t> frame_id() const { return frame_id_; }
  /// True between a request and the switch that answers it.
  bool awaiting_switch() const { return requested_at_.has_value(); }

 private:
  SubmapTriggerOptions options_;
  std::optional<uint32_t> frame_id_;
  Eigen::Vector3d last_p_ = Eigen::Vector3d::Zero();
  double distance_m_ = 0.0;
  std::optional<Time> requested_at_;
  bool pending_restart_ = false;
};

}  // namespace rover::mapd

#endif  // ROVER_FIRMWARE_MAPD_SUBMAP_TRIGGER_H_
