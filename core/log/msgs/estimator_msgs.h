#ifndef ROVER_CORE_LOG_MSGS_ESTIMATOR_MSGS_H_
#define ROVER_CORE_LOG_MSGS_ESTIMATOR_MSGS_H_

// rover_msgs: the local reference filter's inputs and outputs, exactly as the
// filter saw and produced them, so that a log replays bit-exactly.
//
// Every input carries `sequence`, its position in the filter's input order
// (0, 1, 2, ... over all input kinds): the kinds are logged on separate
// topics, and replay merges them back by sequence. Times are int64
// nanoseconds of CLOCK_MONOTONIC (the firmware's Time), doubles are stored
// as IEEE float64, so nothing is rounded on the way. Quaternions are stored
// x, y, z, w (Eigen's coefficient order). Matrices are row-major.

#include <array>
#include <cstdint>
#include <string_view>

#include "core/log/cdr/cdr_reader.h"
#include "core/log/cdr/cdr_writer.h"
#include "core/log/msgs/message_traits.h"

namespace rover::log {
namespace rover_msgs {

/// rover_msgs/msg/EstimatorImu: one IMU reading given to the filter.
struct EstimatorImu {
  uint64_t sequence = 0;
  int64_t stamp_ns = 0;
  std::array<double, 3> angular_velocity_rad_s{};
  std::array<double, 3> linear_acceleration_m_s2{};

  friend bool operator==(const EstimatorImu&, const EstimatorImu&) = default;
};

/// rover_msgs/msg/EstimatorEvent: a stamped request without payload: a
/// camera clone trigger, a frame-switch request or a pose-report request.
struct EstimatorEvent {
  static constexpr uint8_t kCloneTrigger = 0;
  static constexpr uint8_t kFrameSwitchRequest = 1;
  static constexpr uint8_t kPoseReportRequest = 2;
  uint64_t sequence = 0;
  int64_t stamp_ns = 0;
  uint8_t kind = kCloneTrigger;
  uint64_t request_id = 0;  ///< pose-report requests only

  friend bool operator==(const EstimatorEvent&, const EstimatorEvent&) = default;
};

/// rover_msgs/msg/EstimatorRelativePose: a VO relative pose given to the filter.
struct EstimatorRelativePose {
  uint64_t sequence = 0;
  int64_t stamp_ns = 0;  ///< delivery
  int64_t from_stamp_ns = 0;
  int64_t to_stamp_ns = 0;
  std::array<double, 3> p_from_to_m{};
  std::array<double, 4> q_from_to_xyzw{0.0, 0.0, 0.0, 1.0};
  std::array<double, 36> covariance{};  ///< [n_p; n_theta], row-major
  bool to_is_keyframe = false;
  int64_t oldest_keyframe_stamp_ns = 0;

  friend bool operator==(const EstimatorRelativePose&, const EstimatorRelativePose&) = default;
};

/// rover_msgs/msg/EstimatorWheelSpeeds: wheel rates (FL, FR, RL, RR) given to the filter.
struct EstimatorWheelSpeeds {
  uint64_t sequence = 0;
  int64_t stamp_ns = 0;
  std::array<double, 4> wheel_rate_rad_s{};

  friend bool operator==(const EstimatorWheelSpeeds&, const EstimatorWheelSpeeds&) = default;
};

/// rover_msgs/msg/EstimatorState: the filter's full output after one IMU sample.
struct EstimatorState {
  uint64_t sequence = 0;  ///< of the IMU input that produced it
  int64_t stamp_ns = 0;
  uint32_t frame_id = 0;
  uint32_t status = 0;  ///< EskfStatusFlag bits
  std::array<double, 3> p_local_body_m{};
  std::array<double, 3> v_local_m_s{};
  std::array<double, 4> q_local_body_xyzw{0.0, 0.0, 0.0, 1.0};
  std::array<double, 3> accel_bias_m_s2{};
  std::array<double, 3> gyro_bias_rad_s{};
  std::array<double, 3> angular_velocity_body_rad_s{};
  std::array<double, 225> covariance{};  ///< 15 x 15 over [dp dv dtheta dba dbg], row-major

  friend bool operator==(const EstimatorState&, const EstimatorState&) = default;
};

/// rover_msgs/msg/EstimatorFrameSwitch: a frame-of-reference switch record.
struct EstimatorFrameSwitch {
  uint64_t sequence = 0;  ///< of the request that produced it
  int64_t stamp_ns = 0;
  uint32_t old_frame_id = 0;
  uint32_t new_frame_id = 0;
  std::array<double, 3> p_old_new_m{};
  double yaw_old_new_rad = 0.0;
  std::array<double, 16> covariance{};  ///< 4 x 4 over [dp; dyaw], row-major

  friend bool operator==(const EstimatorFrameSwitch&, const EstimatorFrameSwitch&) = default;
};

void Serialize(const EstimatorImu& msg, CdrWriter& writer);
void Serialize(const EstimatorEvent& msg, CdrWriter& writer);
void Serialize(const EstimatorRelativePose& msg, CdrWriter& writer);
void Serialize(const EstimatorWheelSpeeds& msg, CdrWriter& writer);
void Serialize(const EstimatorState& msg, CdrWriter& writer);
void Serialize(const EstimatorFrameSwitch& msg, CdrWriter& writer);
bool Deserialize(CdrReader& reader, EstimatorImu* msg);
bool Deserialize(CdrReader& reader, EstimatorEvent* msg);
bool Deserialize(CdrReader& reader, EstimatorRelativePose* msg);
bool Deserialize(CdrReader& reader, EstimatorWheelSpeeds* msg);
bool Deserialize(CdrReader& reader, EstimatorState* msg);
bool Deserialize(CdrReader& reader, EstimatorFrameSwitch* msg);

}  // namespace rover_msgs

#define ROVER_ESTIMATOR_MSG_TRAITS(Type)                               \
  template <>                                                          \
  struct MessageTraits<rover_msgs::Type> {                             \
    static constexpr std::string_view kName = "rover_msgs/msg/" #Type; \
    static std::string_view Definition();                              \
  };
ROVER_ESTIMATOR_MSG_TRAITS(EstimatorImu)
ROVER_ESTIMATOR_MSG_TRAITS(EstimatorEvent)
ROVER_ESTIMATOR_MSG_TRAITS(EstimatorRelativePose)
ROVER_ESTIMATOR_MSG_TRAITS(EstimatorWheelSpeeds)
ROVER_ESTIMATOR_MSG_TRAITS(EstimatorState)
ROVER_ESTIMATOR_MSG_TRAITS(EstimatorFrameSwitch)
#undef ROVER_ESTIMATOR_MSG_TRAITS

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_MSGS_ESTIMATOR_MSGS_H_
