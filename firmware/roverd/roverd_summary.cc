#include "firmware/roverd/roverd_summary.h"

#include <cstdio>
#include <string>

namespace rover::roverd {
namespace {

std::string Fixed(double v, int digits) {
  char text[48];
  std::snprintf(text, sizeof(text), "%.*f", digits, v);
  return text;
}

}  // namespace

void PrintRoverdStats(const RoverdStats& s, const std::optional<MapdLinkStats>& mapd_link,
                      std::ostream& out) {
  out << "  IMU     " << s.imu_samples << " samples, " << s.imu_drops << " dropped, "
      << s.imu_errors << " errors\n";
  out << "  camera  " << s.frames << " frames, " << s.frame_drops << " dropped; VO "
      << s.vo_measurements << " relative poses (" << s.vo.keyframes << " keyframes, "
      << s.vo.restarts << " restarts, " << s.vo.Count(estimator::vo::VoStatus::kTextureless)
      << " textureless); " << s.images_logged << " images logged (" << s.image_log_drops
      << " dropped)\n";
  out << "  CAN     " << s.can.syncs << " SYNC periods, " << s.wheel_readings << " wheel readings, "
      << s.can.incomplete << " incomplete, " << s.can_errors << " errors\n";
  std::string reasons;
  for (int k = 0; k <= static_cast<int>(estimator::RejectReason::kNumerical); ++k) {
    const auto reason = static_cast<estimator::RejectReason>(k);
    const uint64_t n = s.filter.Rejected(estimator::InputKind::kRelativePose, reason);
    if (n == 0) continue;
    reasons += std::string(reasons.empty() ? " (" : ", ") + estimator::ToString(reason) + " " +
               std::to_string(n);
  }
  if (!reasons.empty()) reasons += ")";
  out << "  filter  " << s.loop.inputs << " inputs; relative poses accepted "
      << s.filter.Accepted(estimator::InputKind::kRelativePose) << ", rejected "
      << s.filter.Rejected(estimator::InputKind::kRelativePose) << reasons
      << "; wheel speeds accepted " << s.filter.Accepted(estimator::InputKind::kWheelSpeeds)
      << "; late inputs " << s.loop.late_inputs << ", ring drops " << s.loop.ring_drops << "\n";
  const auto us = [](int64_t ns) { return Fixed(static_cast<double>(ns) / 1000.0, 1); };
  out << "  loop    estimator step wall time p50 " << us(s.step_latency.p50_ns) << " us, p99 "
      << us(s.step_latency.p99_ns) << " us, p99.9 " << us(s.step_latency.p999_ns) << " us, max "
      << us(s.step_latency.max_ns) << " us\n";
  if (s.sample_to_estimate.count > 0) {
    out << "          IMU sample to estimate p50 " << us(s.sample_to_estimate.p50_ns) << " us, p99 "
        << us(s.sample_to_estimate.p99_ns) << " us, p99.9 " << us(s.sample_to_estimate.p999_ns)
        << " us, max " << us(s.sample_to_estimate.max_ns) << " us\n";
  }
  for (const std::string& t : s.thread_reports) out << "  thread  " << t << "\n";
  out << "  health  " << s.health_reports
      << " reports to /diagnostics; last: " << (s.health.empty() ? "(none)" : s.health) << "\n";
  if (mapd_link) {
    const MapdLinkStats& m = *mapd_link;
    out << "  mapd    " << m.poses_published << " estimates and " << m.frames_published
        << " stereo pairs published (" << m.publish_drops << " dropped); " << m.requests
        << " frame-switch requests (" << m.requests_refused << " refused)\n";
  }
}

}  // namespace rover::roverd
