#ifndef ROVER_ESTIMATOR_IO_ESTIMATOR_LOG_RECORDS_H_
#define ROVER_ESTIMATOR_IO_ESTIMATOR_LOG_RECORDS_H_

// The local reference filter's inputs and outputs as flight-log records
// (rover_msgs Estimator*, see core/log/msgs/estimator_msgs.h), both ways, and
// the topics roverd logs them on. The conversions are exact: every double is
// copied, never recomputed, so a replay of the records is bit-exact.

#include <cstdint>
#include <optional>

#include "core/log/msgs/estimator_msgs.h"
#include "estimator/eskf/eskf_input.h"
#include "estimator/eskf/eskf_output.h"

namespace rover::estimator::io {

/// Topics of the estimator's log records.
inline constexpr const char* kImuInputTopic = "/estimator/input/imu";
inline constexpr const char* kEventInputTopic = "/estimator/input/event";
inline constexpr const char* kRelativePoseInputTopic = "/estimator/input/relative_pose";
inline constexpr const char* kWheelSpeedsInputTopic = "/estimator/input/wheel_speeds";
inline constexpr const char* kStateTopic = "/estimator/state";
inline constexpr const char* kFrameSwitchRecordTopic = "/estimator/frame_switch_record";
/// For viewers and rover-eval: the pose as nav_msgs/Odometry and the switch
/// transforms as geometry_msgs/TransformStamped.
inline constexpr const char* kOdometryTopic = "/estimator/odometry";
inline constexpr const char* kFrameSwitchTopic = "/estimator/frame_switch";
/// Metadata record holding ToYaml(EskfOptions) under the key "yaml".
inline constexpr const char* kOptionsMetadata = "estimator_options";
// Inputs to records, with their position in the filter's input order.
log::rover_msgs::EstimatorImu ToMsg(const ImuMeasurement& m, uint64_t sequence);
log::rover_msgs::EstimatorRelativePose ToMsg(const RelativePoseMeasurement& m, uint64_t sequence);
log::rover_msgs::EstimatorWheelSpeeds ToMsg(const WheelSpeedMeasurement& m, uint64_t sequence);
log::rover_msgs::EstimatorEvent ToMsg(const CloneTrigger& m, uint64_t sequence);
log::rover_msgs::EstimatorEvent ToMsg(const FrameSwitchRequest& m, uint64_t sequence);
log::rover_msgs::EstimatorEvent ToMsg(const PoseReportRequest& m, uint64_t sequence);
// Outputs to records, with the sequence of the input that produced them.
log::rover_msgs::EstimatorState ToMsg(const EskfOutput& output, uint64_t sequence);
log::rover_msgs::EstimatorFrameSwitch ToMsg(const FrameSwitchRecord& record, uint64_t sequence);

// Records back to inputs (exact inverses of ToMsg).
ImuMeasurement FromMsg(const log::rover_msgs::EstimatorImu& msg);
RelativePoseMeasurement FromMsg(const log::rover_msgs::EstimatorRelativePose& msg);
WheelSpeedMeasurement FromMsg(const log::rover_msgs::EstimatorWheelSpeeds& msg);
/// nullopt for an unknown event kind.
std::optional<EskfInput> FromMsg(const log::rover_msgs::EstimatorEvent& msg);

}  // namespace rover::estimator::io

#endif  // ROVER_ESTIMATOR_IO_ESTIMATOR_LOG_RECORDS_H_
