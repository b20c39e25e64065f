#include "core/log/msgs/estimator_msgs.h"

#include "core/log/msgs/definitions.h"

namespace rover::log {
namespace rover_msgs {

void Serialize(const EstimatorImu& msg, CdrWriter& writer) {
  writer.WriteU64(msg.sequence);
  writer.WriteI64(msg.stamp_ns);
  writer.WriteF64Array(msg.angular_velocity_rad_s);
  writer.WriteF64Array(msg.linear_acceleration_m_s2);
}

void Serialize(const EstimatorEvent& msg, CdrWriter& writer) {
  writer.WriteU64(msg.sequence);
  writer.WriteI64(msg.stamp_ns);
  writer.WriteU8(msg.kind);
  writer.WriteU64(msg.request_id);
}

void Serialize(const EstimatorRelativePose& msg, CdrWriter& writer) {
  writer.WriteU64(msg.sequence);
  writer.WriteI64(msg.stamp_ns);
  writer.WriteI64(msg.from_stamp_ns);
  writer.WriteI64(msg.to_stamp_ns);
  writer.WriteF64Array(msg.p_from_to_m);
  writer.WriteF64Array(msg.q_from_to_xyzw);
  writer.WriteF64Array(msg.covariance);
  writer.WriteBool(msg.to_is_keyframe);
  writer.WriteI64(msg.oldest_keyframe_stamp_ns);
}

void Serialize(const EstimatorWheelSpeeds& msg, CdrWriter& writer) {
  writer.WriteU64(msg.sequence);
  writer.WriteI64(msg.stamp_ns);
  writer.WriteF64Array(msg.wheel_rate_rad_s);
}

void Serialize(const EstimatorState& msg, CdrWriter& writer) {
  writer.WriteU64(msg.sequence);
  writer.WriteI64(msg.stamp_ns);
  writer.WriteU32(msg.frame_id);
  writer.WriteU32(msg.status);
  writer.WriteF64Array(msg.p_local_body_m);
  writer.WriteF64Array(msg.v_local_m_s);
  writer.WriteF64Array(msg.q_local_body_xyzw);
  writer.WriteF64Array(msg.accel_bias_m_s2);
  writer.WriteF64Array(msg.gyro_bias_rad_s);
  writer.WriteF64Array(msg.angular_velocity_body_rad_s);
  writer.WriteF64Array(msg.covariance);
}

void Serialize(const EstimatorFrameSwitch& msg, CdrWriter& writer) {
  writer.WriteU64(msg.sequence);
  writer.WriteI64(msg.stamp_ns);
  writer.WriteU32(msg.old_frame_id);
  writer.WriteU32(msg.new_frame_id);
  writer.WriteF64Array(msg.p_old_new_m);
  writer.WriteF64(msg.yaw_old_new_rad);
  writer.WriteF64Array(msg.covariance);
}

bool Deserialize(CdrReader& reader, EstimatorImu* msg) {
  return reader.ReadU64("sequence", &msg->sequence) && reader.ReadI64("stamp_ns", &msg->stamp_ns) &&
         reader.ReadF64Array("angular_velocity_rad_s", msg->angular_velocity_rad_s) &&
         reader.ReadF64Array("linear_acceleration_m_s2", msg->linear_acceleration_m_s2);
}

bool Deserialize(CdrReader& reader, EstimatorEvent* msg) {
  return reader.ReadU64("sequence", &msg->sequence) && reader.ReadI64("stamp_ns", &msg->stamp_ns) &&
         reader.ReadU8("kind", &msg->kind) && reader.ReadU64("request_id", &msg->request_id);
}

bool Deserialize(CdrReader& reader, EstimatorRelativePose* msg) {
  return reader.ReadU64("sequence", &msg->sequence) && reader.ReadI64("stamp_ns", &msg->stamp_ns) &&
         reader.ReadI64("from_stamp_ns", &msg->from_stamp_ns) &&
         reader.ReadI64("to_stamp_ns", &msg->to_stamp_ns) &&
         reader.ReadF64Array("p_from_to_m", msg->p_from_to_m) &&
         reader.ReadF64Array("q_from_to_xyzw", msg->q_from_to_xyzw) &&
         reader.ReadF64Array("covariance", msg->covariance) &&
         reader.ReadBool("to_is_keyframe", &msg->to_is_keyframe) &&
         reader.ReadI64("oldest_keyframe_stamp_ns", &msg->oldest_keyframe_stamp_ns);
}

bool Deserialize(CdrReader& reader, EstimatorWheelSpeeds* msg) {
  return reader.ReadU64("sequence", &msg->sequence) && reader.ReadI64("stamp_ns", &msg->stamp_ns) &&
         reader.ReadF64Array("wheel_rate_rad_s", msg->wheel_rate_rad_s);
}

bool Deserialize(CdrReader& reader, EstimatorState* msg) {
  return reader.ReadU64("sequence", &msg->sequence) && reader.ReadI64("stamp_ns", &msg->stamp_ns) &&
         reader.ReadU32("frame_id", &msg->frame_id) && reader.ReadU32("status", &msg->status) &&
         reader.ReadF64Array("p_local_body_m", msg->p_local_body_m) &&
         reader.ReadF64Array("v_local_m_s", msg->v_local_m_s) &&
         reader.ReadF64Array("q_local_body_xyzw", msg->q_local_body_xyzw) &&
         reader.ReadF64Array("accel_bias_m_s2", msg->accel_bias_m_s2) &&
         reader.ReadF64Array("gyro_bias_rad_s", msg->gyro_bias_rad_s) &&
         reader.ReadF64Array("angular_velocity_body_rad_s", msg->angular_velocity_body_rad_s) &&
         reader.ReadF64Array("covariance", msg->covariance);
}

bool Deserialize(CdrReader& reader, EstimatorFrameSwitch* msg) {
  return reader.ReadU64("sequence", &msg->sequence) && reader.ReadI64("stamp_ns", &msg->stamp_ns) &&
         reader.ReadU32("old_frame_id", &msg->old_frame_id) &&
         reader.ReadU32("new_frame_id", &msg->new_frame_id) &&
         reader.ReadF64Array("p_old_new_m", msg->p_old_new_m) &&
         reader.ReadF64("yaw_old_new_rad", &msg->yaw_old_new_rad) &&
         reader.ReadF64Array("covariance", msg->covariance);
}

}  // namespace rover_msgs

#define ROVER_ESTIMATOR_MSG_DEFINITION(Type)                       \
  std::string_view MessageTraits<rover_msgs::Type>::Definition() { \
    return internal::CachedDefinition<rover_msgs::Type>();         \
  }
ROVER_ESTIMATOR_MSG_DEFINITION(EstimatorImu)
ROVER_ESTIMATOR_MSG_DEFINITION(EstimatorEvent)
ROVER_ESTIMATOR_MSG_DEFINITION(EstimatorRelativePose)
ROVER_ESTIMATOR_MSG_DEFINITION(EstimatorWheelSpeeds)
ROVER_ESTIMATOR_MSG_DEFINITION(EstimatorState)
ROVER_ESTIMATOR_MSG_DEFINITION(EstimatorFrameSwitch)
#undef ROVER_ESTIMATOR_MSG_DEFINITION

}  // namespace rover::log
