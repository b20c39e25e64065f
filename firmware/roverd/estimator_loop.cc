#include "firmware/roverd/estimator_loop.h"

#include <chrono>
#include <cstdio>
#include <thread>
#include <type_traits>
#include <utility>
#include <variant>

namespace rover::roverd {
namespace {

namespace msgs = log::rover_msgs;

// "local/rover/<id>" without allocating.
log::FrameId LocalFrameName(uint32_t frame_id) {
  char text[32];
  const int n = std::snprintf(text, sizeof(text), "local/rover/%u", frame_id);
  return log::FrameId::Truncated(std::string_view(text, static_cast<std::size_t>(n)));
}

}  // namespace

EstimatorLogChannels EstimatorLogChannels::Add(log::FlightLog* log,
                                               const estimator::EskfOptions& options) {
  EstimatorLogChannels c;
  c.imu = log->AddChannel<msgs::EstimatorImu>(kImuInputTopic);
  c.events = log->AddChannel<msgs::EstimatorEvent>(kEventInputTopic);
  c.relative_poses = log->AddChannel<msgs::EstimatorRelativePose>(kRelativePoseInputTopic);
  c.wheel_speeds = log->AddChannel<msgs::EstimatorWheelSpeeds>(kWheelSpeedsInputTopic);
  c.states = log->AddChannel<msgs::EstimatorState, 2048, 2048>(kStateTopic);
  c.frame_switches = log->AddChannel<msgs::EstimatorFrameSwitch>(kFrameSwitchRecordTopic);
  c.odometry = log->AddChannel<log::nav_msgs::Odometry>(kOdometryTopic);
  c.frame_switch_transforms =
      log->AddChannel<log::geometry_msgs::TransformStamped>(kFrameSwitchTopic);
  log->WriteMetadata(kOptionsMetadata, {{"yaml", estimator::ToYaml(options)}});
  return c;
}

EstimatorLoop::EstimatorLoop(const estimator::EskfOptions& options,
                             const EstimatorLogChannels& channels, EstimatorListener* listener,
                             bool lockstep)
    : filter_(options, this), channels_(channels), listener_(listener), lockstep_(lockstep) {}

void EstimatorLoop::WaitForLogRoom() const {
  const auto half_full = [](const auto* channel) {
    return channel != nullptr && channel->queued() * 2 >= channel->capacity();
  };
  const auto any_half_full = [&] {
    return half_full(channels_.imu) || half_full(channels_.events) ||
           half_full(channels_.relative_poses) || half_full(channels_.wheel_speeds) ||
           half_full(channels_.states) || half_full(channels_.frame_switches) ||
           half_full(channels_.odometry) || half_full(channels_.frame_switch_transforms);
  };
  while (any_half_full()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
}

bool EstimatorLoop::PushRelativePose(const estimator::RelativePoseMeasurement& m) {
  if (relative_poses_.TryPush(m)) return true;
  ring_drops_.fetch_add(1, std::memory_order_relaxed);
  return false;
}

bool EstimatorLoop::PushWheelSpeeds(const estimator::WheelSpeedMeasurement& m) {
  if (wheel_speeds_.TryPush(m)) return true;
  ring_drops_.fetch_add(1, std::memory_order_relaxed);
  return false;
}

bool EstimatorLoop::PushCloneTrigger(const estimator::CloneTrigger& m) {
  if (clone_triggers_.TryPush(m)) return true;
  ring_drops_.fetch_add(1, std::memory_order_relaxed);
  return false;
}

bool EstimatorLoop::PushFrameSwitchRequest(const estimator::FrameSwitchRequest& m) {
  if (requests_.TryPush(m)) return true;
  ring_drops_.fetch_add(1, std::memory_order_relaxed);
  return false;
}

void EstimatorLoop::Collect() {
  // A ring's head that does not fit waits in the ring for the next Step().
  const auto drain = [this](auto& ring) {
    for (const auto* item = ring.Front(); item != nullptr; item = ring.Front()) {
      if (!merger_.Push(estimator::EskfInput(*item))) {
        pending_full_.fetch_add(1, std::memory_order_relaxed);
        return;
      }
      ring.PopFront();
    }
  };
  drain(clone_triggers_);
  drain(wheel_speeds_);
  drain(relative_poses_);
  drain(requests_);
}

void EstimatorLoop::Step(const estimator::ImuMeasurement& imu) {
  if (lockstep_) WaitForLogRoom();
  Collect();
  merger_.Step(imu, [this](const estimator::EskfInput& input) { Feed(input); });
  late_inputs_.store(merger_.late_inputs(), std::memory_order_relaxed);
}

void EstimatorLoop::Drain() {
  Collect();
  merger_.Drain([this](const estimator::EskfInput& input) { Feed(input); });
}

void EstimatorLoop::Feed(const estimator::EskfInput& input) {
  current_sequence_ = inputs_.load(std::memory_order_relaxed);
  LogInput(input, current_sequence_);
  inputs_.store(current_sequence_ + 1, std::memory_order_relaxed);
  filter_.Process(input);
}

void EstimatorLoop::LogInput(const estimator::EskfInput& input, uint64_t sequence) {
  namespace io = estimator::io;
  std::visit(
      [&](const auto& m) {
        using T = std::decay_t<decltype(m)>;
        if constexpr (std::is_same_v<T, estimator::ImuMeasurement>) {
          if (channels_.imu != nullptr) channels_.imu->Log(m.stamp, io::ToMsg(m, sequence));
        } else if constexpr (std::is_same_v<T, estimator::RelativePoseMeasurement>) {
          if (channels_.relative_poses != nullptr) {
            channels_.relative_poses->Log(m.stamp, io::ToMsg(m, sequence));
          }
        } else if constexpr (std::is_same_v<T, estimator::WheelSpeedMeasurement>) {
          if (channels_.wheel_speeds != nullptr) {
            channels_.wheel_speeds->Log(m.stamp, io::ToMsg(m, sequence));
          }
        } else {
          if (channels_.events != nullptr) channels_.events->Log(m.stamp, io::ToMsg(m, sequence));
        }
      },
      input);
}

void EstimatorLoop::OnState(const estimator::EskfOutput& output) {
  states_.fetch_add(1, std::memory_order_relaxed);
  if (channels_.states != nullptr) {
    channels_.states->Log(output.stamp, estimator::io::ToMsg(output, current_sequence_));
  }
  if (channels_.odometry != nullptr) {
    log::nav_msgs::Odometry o;
    o.header.stamp = log::ToRosTime(output.stamp);
    o.header.frame_id = LocalFrameName(output.frame_id);
    o.child_frame_id = log::FrameId::Truncated("body");
    o.pose.pose.position = {output.p_local_body.x(), output.p_local_body.y(),
                            output.p_local_body.z()};
    const Eigen::Quaterniond& q = output.q_local_body;
    o.pose.pose.orientation = {q.x(), q.y(), q.z(), q.w()};
    // ROS order [x y z rx ry rz]: the position and attitude blocks.
    for (int r = 0; r < 6; ++r) {
      for (int c = 0; c < 6; ++c) {
        const int rr = r < 3 ? r : r + 3, cc = c < 3 ? c : c + 3;
        o.pose.covariance[static_cast<std::size_t>(r * 6 + c)] = output.covariance(rr, cc);
      }
    }
    const Eigen::Vector3d v_body = q.conjugate() * output.v_local_m_s;
    o.twist.twist.linear = {v_body.x(), v_body.y(), v_body.z()};
    o.twist.twist.angular = {output.angular_velocity_body_rad_s.x(),
                             output.angular_velocity_body_rad_s.y(),
                             output.angular_velocity_body_rad_s.z()};
    channels_.odometry->Log(output.stamp, o);
  }
  if (listener_ != nullptr) listener_->OnState(output);
}

void EstimatorLoop::OnFrameSwitch(const estimator::FrameSwitchRecord& record) {
  if (channels_.frame_switches != nullptr) {
    channels_.frame_switches->Log(record.stamp, estimator::io::ToMsg(record, current_sequence_));
  }
  if (channels_.frame_switch_transforms != nullptr) {
    log::geometry_msgs::TransformStamped t;
    t.header.stamp = log::ToRosTime(record.stamp);
    t.header.frame_id = LocalFrameName(record.old_frame_id);
    t.child_frame_id = LocalFrameName(record.new_frame_id);
    t.transform.translation = {record.p_old_new.x(), record.p_old_new.y(), record.p_old_new.z()};
    const Eigen::Quaterniond q(Eigen::AngleAxisd(record.yaw_old_new_rad, Eigen::Vector3d::UnitZ()));
    t.transform.rotation = {q.x(), q.y(), q.z(), q.w()};
    channels_.frame_switch_transforms->Log(record.stamp, t);
  }
  if (listener_ != nullptr) listener_->OnFrameSwitch(record);
}

void EstimatorLoop::OnPoseReport(const estimator::PoseReport& /*report*/) {
  // Pose reports go to mapd's graph; nothing requests them yet.
}

void EstimatorLoop::OnReject(const estimator::RejectRecord& /*record*/) {
  // Counted in the filter's health, which the health report publishes.
}

EstimatorLoopStats EstimatorLoop::stats() const {
  EstimatorLoopStats s;
  s.inputs = inputs_.load(std::memory_order_relaxed);
  s.states = states_.load(std::memory_order_relaxed);
  s.ring_drops = ring_drops_.load(std::memory_order_relaxed);
  s.pending_full = pending_full_.load(std::memory_order_relaxed);
  s.late_inputs = late_inputs_.load(std::memory_order_relaxed);
  return s;
}

}  // namespace rover::roverd
