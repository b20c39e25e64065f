#include "hil/sim/estimator_feed/filter_feed.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "drivers/can/canopen_wheel_protocol.h"
#include "drivers/can/wheel_speed_decoder.h"
#include "estimator/feed/input_order.h"
#include "hil/sim/dataset/dataset_generator.h"
#include "hil/sim/sensors/gpio_edge_model.h"
#include "hil/sim/sensors/imu_model.h"
#include "hil/sim/world/world.h"

namespace rover::sim {
namespace {

TruthSample TruthOf(Time stamp, const TrajectorySample& s) {
  TruthSample t;
  t.stamp = stamp;
  t.p_world_body = s.p_world_body;
  t.q_world_body = s.q_world_body;
  t.v_world_m_s = s.v_world_m_s;
  return t;
}

}  // namespace

FilterFeedOptions FilterFeedOptions::Load(const ConfigNode& node) {
  FilterFeedOptions o;
  o.wheels_enabled = node.Get<bool>("wheels_enabled", o.wheels_enabled);
  o.max_duration_s = node.GetInRange<double>("max_duration_s", 0.0, 1e6, o.max_duration_s);
  o.frame_switch_distance_m =
      node.GetInRange<double>("frame_switch_distance_m", 0.0, 1e4, o.frame_switch_distance_m);
  if (node.Has("vo")) o.vo = SyntheticVoOptions::Load(node.Child("vo"));
  return o;
}

void FilterFeedOptions::Validate() const {
  if (!(max_duration_s >= 0.0)) {
    throw std::invalid_argument("FilterFeedOptions: max_duration_s must not be negative");
  }
  if (!(frame_switch_distance_m >= 0.0)) {
    throw std::invalid_argument("FilterFeedOptions: frame_switch_distance_m must not be negative");
  }
  vo.Validate();
}

FilterFeed::FilterFeed(FilterFeed&&) noexcept = default;
FilterFeed& FilterFeed::operator=(FilterFeed&&) noexcept = default;
FilterFeed::~FilterFeed() = default;

FilterFeed::FilterFeed(const Scenario& scenario, uint64_t seed, const FilterFeedOptions& options)
    : scenario_(scenario), seed_(seed), options_(options) {
  options_.Validate();
  // The recording rover as GenerateDataset builds it.
  const World world = World::Generate(scenario.world, seed);
  trajectory_ = std::make_unique<RoverTrajectory>(scenario.route, world.terrain);
  const RoverTrajectory& trajectory = *trajectory_;
  if (!scenario.wheels_config.empty()) {
    wheel_options_ = WheelOdometryModelOptions::LoadFile(scenario.wheels_config);
  }
  start_ = kDatasetStartTime;
  const double duration_s = options_.max_duration_s > 0.0
                                ? std::min(options_.max_duration_s, trajectory.duration_s())
                                : trajectory.duration_s();
  end_ = start_ + Duration::FromSeconds(duration_s);

  // IMU samples, their truth and the driven distance (for frame switches).
  ImuModelOptions imu_options = scenario.imu;
  imu_options.seed = scenario.imu.seed ^ (seed * 0x9E3779B97F4A7C15ULL);
  ImuModel imu(imu_options, start_);
  Eigen::Vector2d last_xy = trajectory.Evaluate(0.0).p_world_body.head<2>();
  double next_switch_m = options_.frame_switch_distance_m;
  for (;;) {
    TrajectorySample truth;
    const drivers::ImuSample sample = imu.Next(trajectory, &truth);
    if (sample.stamp >= end_) break;
    estimator::ImuMeasurement m;
    m.stamp = sample.stamp;
    m.angular_velocity_rad_s = sample.angular_velocity_rad_s;
    m.linear_acceleration_m_s2 = sample.linear_acceleration_m_s2;
    inputs_.push_back(m);
    TruthSample t = TruthOf(sample.stamp, truth);
    t.gyro_bias_rad_s = imu.gyro_bias_rad_s();
    t.accel_bias_m_s2 = imu.accel_bias_m_s2();
    imu_truth_.push_back(t);
    ++counts_.imu;
    distance_m_ += (truth.p_world_body.head<2>() - last_xy).norm();
    last_xy = truth.p_world_body.head<2>();
    if (options_.frame_switch_distance_m > 0.0 && distance_m_ >= next_switch_m) {
      inputs_.push_back(estimator::FrameSwitchRequest{m.stamp});
      ++counts_.frame_switches;
      while (next_switch_m <= distance_m_) next_switch_m += options_.frame_switch_distance_m;
    }
  }

  // Wheel drives on the CAN bus, decoded as the SocketCAN side would.
  WheelOdometryModel wheels(wheel_options_, trajectory, world.terrain, start_);
  std::vector<drivers::CanFrame> frames;
  wheels.Advance(end_, &frames, &wheel_truth_);
  if (options_.wheels_enabled) {
    for (const drivers::WheelSpeeds& w : drivers::DecodeWheelSpeeds(frames)) {
      inputs_.push_back(estimator::WheelSpeedMeasurement{w.stamp, w.wheel_rate_rad_s});
      ++counts_.wheel_speeds;
    }
  }

  // Camera triggers (the GPIO model's phase) and the VO on them.
  const GpioEdgeModel gpio(scenario.gpio, start_);
  std::vector<VoFrame> vo_frames;
  for (const Time t : gpio.CameraTriggerTimes(start_, end_)) {
    inputs_.push_back(estimator::CloneTrigger{t});
    ++counts_.clone_triggers;
    const TruthSample truth = TruthAt(t);
    trigger_truth_.push_back(truth);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = truth.q_world_body.toRotationMatrix();
    T.translation() = truth.p_world_body;
    vo_frames.push_back({t, T});
  }
  for (const estimator::RelativePoseMeasurement& m :
       RunSyntheticVo(options_.vo, vo_frames, seed, &counts_.vo)) {
    // A measurement delivered after the end of the feed is never seen.
    if (m.stamp >= end_) continue;
    inputs_.push_back(m);
    ++counts_.relative_poses;
  }

  // The filter's one input order (estimator/feed), as roverd merges it.
  estimator::SortInputs(&inputs_);
}

TruthSample FilterFeed::TruthAt(Time t) const {
  return TruthOf(t, trajectory_->Evaluate((t - start_).ToSeconds()));
}

}  // namespace rover::sim
