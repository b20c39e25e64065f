#include "estimator/io/estimator_log_records.h"

namespace rover::estimator::io {
namespace {

namespace msgs = log::rover_msgs;

template <std::size_t N>
void CopyVector(const Eigen::Vector3d& v, std::array<double, N>* out) {
  for (int i = 0; i < 3; ++i) (*out)[static_cast<std::size_t>(i)] = v[i];
}

void CopyQuaternion(const Eigen::Quaterniond& q, std::array<double, 4>* out) {
  *out = {q.x(), q.y(), q.z(), q.w()};
}

template <typename Matrix, std::size_t N>
void CopyRowMajor(const Matrix& m, std::array<double, N>* out) {
  std::size_t k = 0;
  for (int r = 0; r < m.rows(); ++r) {
    for (int c = 0; c < m.cols(); ++c) (*out)[k++] = m(r, c);
  }
}
Eigen::Vector3d Vector(const std::array<double, 3>& a) { return {a[0], a[1], a[2]}; }

}  // namespace

msgs::EstimatorImu ToMsg(const ImuMeasurement& m, uint64_t sequence) {
  msgs::EstimatorImu r;
  r.sequence = sequence;
  r.stamp_ns = m.stamp.nanoseconds();
  CopyVector(m.angular_velocity_rad_s, &r.angular_velocity_rad_s);
  CopyVector(m.linear_acceleration_m_s2, &r.linear_acceleration_m_s2);
  return r;
}

msgs::EstimatorRelativePose ToMsg(const RelativePoseMeasurement& m, uint64_t sequence) {
  msgs::EstimatorRelativePose r;
  r.sequence = sequence;
  r.stamp_ns = m.stamp.nanoseconds();
  r.from_stamp_ns = m.from_stamp.nanoseconds();
  r.to_stamp_ns = m.to_stamp.nanoseconds();
  CopyVector(m.p_from_to, &r.p_from_to_m);
  CopyQuaternion(m.q_from_to, &r.q_from_to_xyzw);
  CopyRowMajor(m.covariance, &r.covariance);
  r.to_is_keyframe = m.to_is_keyframe;
  r.oldest_keyframe_stamp_ns = m.oldest_keyframe_stamp.nanoseconds();
  return r;
}

msgs::EstimatorWheelSpeeds ToMsg(const WheelSpeedMeasurement& m, uint64_t sequence) {
  msgs::EstimatorWheelSpeeds r;
  r.sequence = sequence;
  r.stamp_ns = m.stamp.nanoseconds();
  r.wheel_rate_rad_s = m.wheel_rate_rad_s;
  return r;
}

msgs::EstimatorEvent ToMsg(const CloneTrigger& m, uint64_t sequence) {
  return {sequence, m.stamp.nanoseconds(), msgs::EstimatorEvent::kCloneTrigger, 0};
}

msgs::EstimatorEvent ToMsg(const FrameSwitchRequest& m, uint64_t sequence) {
  return {sequence, m.stamp.nanoseconds(), msgs::EstimatorEvent::kFrameSwitchRequest, 0};
}

msgs::EstimatorEvent ToMsg(const PoseReportRequest& m, uint64_t sequence) {
  return {sequence, m.stamp.nanoseconds(), msgs::EstimatorEvent::kPoseReportRequest, m.id};
}

msgs::EstimatorState ToMsg(const EskfOutput& output, uint64_t sequence) {
  msgs::EstimatorState r;
  r.sequence = sequence;
  r.stamp_ns = output.stamp.nanoseconds();
  r.frame_id = output.frame_id;
  r.status = output.status;
  CopyVector(output.p_local_body, &r.p_local_body_m);
  CopyVector(output.v_local_m_s, &r.v_local_m_s);
  CopyQuaternion(output.q_local_body, &r.q_local_body_xyzw);
  CopyVector(output.accel_bias_m_s2, &r.accel_bias_m_s2);
  CopyVector(output.gyro_bias_rad_s, &r.gyro_bias_rad_s);
  CopyVector(output.angular_velocity_body_rad_s, &r.angular_velocity_body_rad_s);
  CopyRowMajor(output.covariance, &r.covariance);
  return r;
}

msgs::EstimatorFrameSwitch ToMsg(const FrameSwitchRecord& record, uint64_t sequence) {
  msgs::EstimatorFrameSwitch r;
  r.sequence = sequence;
  r.stamp_ns = record.stamp.nanoseconds();
  r.old_frame_id = record.old_frame_id;
  r.new_frame_id = record.new_frame_id;
  CopyVector(record.p_old_new, &r.p_old_new_m);
  r.yaw_old_new_rad = record.yaw_old_new_rad;
  CopyRowMajor(record.covariance, &r.covariance);
  return r;
}
ImuMeasurement FromMsg(const msgs::EstimatorImu& msg) {
  ImuMeasurement m;
  m.stamp = Time::FromNanoseconds(msg.stamp_ns);
  m.angular_velocity_rad_s = Vector(msg.angular_velocity_rad_s);
  m.linear_acceleration_m_s2 = Vector(msg.linear_acceleration_m_s2);
  return m;
}

RelativePoseMeasurement FromMsg(const msgs::EstimatorRelativePose& msg) {
  RelativePoseMeasurement m;
  m.stamp = Time::FromNanoseconds(msg.stamp_ns);
  m.from_stamp = Time::FromNanoseconds(msg.from_stamp_ns);
  m.to_stamp = Time::FromNanoseconds(msg.to_stamp_ns);
  m.p_from_to = Vector(msg.p_from_to_m);
  const auto& q = msg.q_from_to_xyzw;
  m.q_from_to = Eigen::Quaterniond(q[3], q[0], q[1], q[2]);  // stored as is, not normalised
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) m.covariance(r, c) = msg.covariance[static_cast<size_t>(r * 6 + c)];
  }
  m.to_is_keyframe = msg.to_is_keyframe;
  m.oldest_keyframe_stamp = Time::FromNanoseconds(msg.oldest_keyframe_stamp_ns);
  return m;
}

WheelSpeedMeasurement FromMsg(const msgs::EstimatorWheelSpeeds& msg) {
  WheelSpeedMeasurement m;
  m.stamp = Time::FromNanoseconds(msg.stamp_ns);
  m.wheel_rate_rad_s = msg.wheel_rate_rad_s;
  return m;
}

std::optional<EskfInput> FromMsg(const msgs::EstimatorEvent& msg) {
  const Time stamp = Time::FromNanoseconds(msg.stamp_ns);
  // Built in place: GCC's -O1 sanitizer builds warn (falsely) about copying
  // a variant temporary into the optional.
  std::optional<EskfInput> out;
  switch (msg.kind) {
    case msgs::EstimatorEvent::kCloneTrigger:
      out.emplace(std::in_place_type<CloneTrigger>, CloneTrigger{stamp});
      break;
    case msgs::EstimatorEvent::kFrameSwitchRequest:
      out.emplace(std::in_place_type<FrameSwitchRequest>, FrameSwitchRequest{stamp});
      break;
    case msgs::EstimatorEvent::kPoseReportRequest:
      out.emplace(std::in_place_type<PoseReportRequest>, PoseReportRequest{stamp, msg.request_id});
      break;
    default:
      break;
  }
  return out;
}

}  // namespace rover::estimator::io
