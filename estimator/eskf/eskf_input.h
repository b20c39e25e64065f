#ifndef ROVER_ESTIMATOR_ESKF_ESKF_INPUT_H_
#define ROVER_ESTIMATOR_ESKF_ESKF_INPUT_H_

// The inputs of the local reference filter. The filter is a pure function of
// the ordered sequence of these records: the runtime merges them by time stamp
// (roverd) or reads them back from a flight log (replay), and the same
// sequence always yields bit-identical outputs.
//
// Frames: `body` is the IMU frame; `local` is the filter's current frame of
// reference (gravity-aligned, z up). Wheel and VO measurements are expressed
// in `body` by their producers (the VO applies the camera extrinsics).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <variant>

#include "core/time/time.h"

namespace rover::estimator {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// One IMU reading in the body frame.
struct ImuMeasurement {
  Time stamp;
  Eigen::Vector3d angular_velocity_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d linear_acceleration_m_s2 = Eigen::Vector3d::Zero();  ///< specific force
};

/// A camera trigger: the filter clones the body pose at exactly `stamp` (the
/// stereo pair's capture time), interpolating between IMU samples.
struct CloneTrigger {
  Time stamp;
};

/// A relative pose between two capture times, body frame at `from_stamp` to
/// body frame at `to_stamp` (T_bodyfrom_bodyto), as the keyframe VO measures it.
/// Noise convention: p_meas = p_true + n_p, R_meas = R_true * Exp(n_theta),
/// `covariance` = Cov([n_p; n_theta]) (translation first, metres and radians).
struct RelativePoseMeasurement {
  Time stamp;       ///< when the VO delivered it (merge key); at or after to_stamp
  Time from_stamp;  ///< capture time of the keyframe (a cloned trigger)
  Time to_stamp;    ///< capture time of the current frame (a cloned trigger)
  Eigen::Vector3d p_from_to = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_from_to = Eigen::Quaterniond::Identity();
  Matrix6d covariance = Matrix6d::Identity();
  /// The VO made `to` a new keyframe: later measurements may start from it, so
  /// its clone is kept. Otherwise the clone is marginalised after the update.
  bool to_is_keyframe = false;
  /// Capture time of the oldest keyframe the VO still holds; keyframe clones
  /// captured before it are marginalised. Zero: not given (clones are then
  /// only dropped when room is needed).
  Time oldest_keyframe_stamp;
};

/// Wheel order of the drives: CANopen node id minus one.
enum WheelPosition : int { kFrontLeft = 0, kFrontRight = 1, kRearLeft = 2, kRearRight = 3 };

/// Angular rates of the four wheels (velocity actual values of the drives),
/// positive when the rover rolls forward, latched at the SYNC at `stamp`.
struct WheelSpeedMeasurement {
  Time stamp;
  std::array<double, 4> wheel_rate_rad_s{};
};

/// Request to move the local frame into the unobservable part (x, y, z, yaw)
/// of the current pose. The filter answers with a FrameSwitchRecord.
struct FrameSwitchRequest {
  Time stamp;
};

/// Request for the current pose in the local frame with its 6x6 covariance
/// (graph factor `v`). The filter answers with a PoseReport carrying `id`.
struct PoseReportRequest {
  Time stamp;
  uint64_t id = 0;
};

/// Any filter input; the order of a sequence of these defines the estimate.
using EskfInput = std::variant<ImuMeasurement, CloneTrigger, RelativePoseMeasurement,
                               WheelSpeedMeasurement, FrameSwitchRequest, PoseReportRequest>;

/// The time stamp of any input (the merge key).
inline Time StampOf(const EskfInput& input) {
  return std::visit([](const auto& m) { return m.stamp; }, input);
}

}  // namespace rover::estimator

#endif  // ROVER_ESTIMATOR_ESKF_ESKF_INPUT_H_
