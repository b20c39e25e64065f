#ifndef ROVER_ESTIMATOR_ESKF_ESKF_HEALTH_H_
#define ROVER_ESTIMATOR_ESKF_ESKF_HEALTH_H_

#include <array>
#include <cstdint>

#include "estimator/eskf/eskf_output.h"

namespace rover::estimator {

inline constexpr int kInputKindCount = 6;
inline constexpr int kRejectReasonCount = 10;

/// Counters of everything the filter accepted, rejected or did, for the
/// health topic and the log. Plain data, copied out by value.
struct EskfHealth {
  /// Accepted inputs per InputKind.
  std::array<uint64_t, kInputKindCount> accepted{};
  /// Rejected inputs per [InputKind][RejectReason].
  std::array<std::array<uint64_t, kRejectReasonCount>, kInputKindCount> rejected{};
  uint64_t imu_gaps = 0;           ///< IMU intervals longer than max_imu_gap_s
  double longest_imu_gap_s = 0.0;  ///< longest interval seen after initialisation
  uint64_t clones_created = 0;
  uint64_t clones_marginalised = 0;  ///< no pending measurement referred to them any more
  uint64_t clones_evicted = 0;       ///< dropped to make room while still possibly referenced
  uint64_t zero_velocity_updates = 0;
  uint64_t frame_switches = 0;
  uint32_t status = 0;  ///< EskfStatusFlag bits of the latest output

  uint64_t Accepted(InputKind kind) const { return accepted[static_cast<size_t>(kind)]; }
  uint64_t Rejected(InputKind kind, RejectReason reason) const {
    return rejected[static_cast<size_t>(kind)][static_cast<size_t>(reason)];
  }
  /// All rejections of one input kind.
  uint64_t Rejected(InputKind kind) const {
    uint64_t sum = 0;
    for (uint64_t n : rejected[static_cast<size_t>(kind)]) sum += n;
    return sum;
  }
};

}  // namespace rover::estimator

#endif  // ROVER_ESTIMATOR_ESKF_ESKF_HEALTH_H_
