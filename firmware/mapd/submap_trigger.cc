#include "firmware/mapd/submap_trigger.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace rover::mapd {

using runtime::topics::SwitchReason;

void SubmapTriggerOptions::Validate() const {
  const auto positive = [](const char* key, double v) {
    if (!(std::isfinite(v) && v > 0.0)) {
      throw std::invalid_argument(std::string("SubmapTriggerOptions.") + key +
                                  ": expected a positive number, found " + std::to_string(v));
    }
  };
  positive("max_distance_m", max_distance_m);
  positive("max_position_sigma_m", max_position_sigma_m);
  positive("request_retry_s", request_retry.ToSeconds());
}

SubmapTrigger::SubmapTrigger(const SubmapTriggerOptions& options) : options_(options) {
  options_.Validate();
}

std::optional<SwitchReason> SubmapTrigger::OnPose(Time stamp, uint32_t frame_id,
                                                  const Eigen::Vector3d& p, double sigma_m) {
  if (!frame_id_ || *frame_id_ != frame_id) {
    // A new local frame (or the first estimate): the switch answered any
    // request, and the distance counts from here.
    frame_id_ = frame_id;
    distance_m_ = 0.0;
    requested_at_.reset();
  } else {
    distance_m_ += (p - last_p_).norm();
  }
  last_p_ = p;
  std::optional<SwitchReason> reason;
  if (pending_restart_) {
    reason = SwitchReason::kRestart;
  } else if (sigma_m > options_.max_position_sigma_m) {
    reason = SwitchReason::kPositionSigma;
  } else if (distance_m_ > options_.max_distance_m) {
    reason = SwitchReason::kDistance;
  }
  if (!reason) return std::nullopt;
  if (requested_at_ && stamp - *requested_at_ < options_.request_retry) return std::nullopt;
  pending_restart_ = false;
  requested_at_ = stamp;
  return reason;
}

}  // namespace rover::mapd
