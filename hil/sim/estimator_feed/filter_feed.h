#ifndef ROVER_HIL_SIM_ESTIMATOR_FEED_FILTER_FEED_H_
#define ROVER_HIL_SIM_ESTIMATOR_FEED_FILTER_FEED_H_

// The simulator-side input of the local reference filter: for a scenario and
// a seed, the complete time-ordered sequence of filter inputs (IMU samples,
// wheel speeds decoded from the CANopen bus, camera clone triggers, synthetic
// keyframe-VO relative poses, optional frame-switch requests) and the ground
// truth to score the filter against. Built up front (an offline harness).
//
// The world, trajectory, IMU and wheel streams are built exactly as
// `rover-sim generate` builds them for the recording rover (world seed =
// seed, IMU seed = scenario IMU seed ^ seed * golden ratio, the scenario's
// wheel file with its own seed, default RoverTrajectoryOptions, time origin
// kDatasetStartTime), so a feed and a dataset of the same scenario and seed
// carry the same samples.
//
// Merge order: the filter's one input order (estimator/feed/input_order.h),
// as roverd's IMU thread merges them.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/config/config.h"
#include "core/time/time.h"
#include "estimator/eskf/eskf_input.h"
#include "hil/sim/estimator_feed/synthetic_vo.h"
#include "hil/sim/motion/rover_trajectory.h"
#include "hil/sim/scenario/scenario.h"
#include "hil/sim/sensors/wheel_odometry_model.h"

namespace rover::sim {

struct FilterFeedOptions {
  /// Wheel speeds from the CAN bus (the wheel model runs either way).
  bool wheels_enabled = true;
  /// Stop after this much simulated time (0: the whole route).
  double max_duration_s = 0.0;
  /// A FrameSwitchRequest each time the driven (horizontal) distance passes
  /// another multiple of this (0: never; the thesis switched every ~7 m).
  double frame_switch_distance_m = 0.0;
  SyntheticVoOptions vo;

  /// Keys (all optional): wheels_enabled, max_duration_s, frame_switch_distance_m
  /// and the map `vo` (SyntheticVoOptions::Load). Ranges checked; the caller
  /// checks for unknown keys.
  static FilterFeedOptions Load(const ConfigNode& node);
  /// Throws std::invalid_argument naming the first bad value.
  void Validate() const;
};

/// True state of the body (IMU) frame in the world frame (gravity-aligned, z up).
struct TruthSample {
  Time stamp;
  Eigen::Vector3d p_world_body = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_world_body = Eigen::Quaterniond::Identity();
  Eigen::Vector3d v_world_m_s = Eigen::Vector3d::Zero();
  /// Additive IMU biases of the sample (IMU samples only; zero elsewhere).
  Eigen::Vector3d gyro_bias_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_bias_m_s2 = Eigen::Vector3d::Zero();
};

/// How many inputs of each kind a feed holds.
struct FilterFeedCounts {
  uint64_t imu = 0;
  uint64_t wheel_speeds = 0;
  uint64_t clone_triggers = 0;
  uint64_t relative_poses = 0;
  uint64_t frame_switches = 0;
  SyntheticVoStats vo;
};

class FilterFeed {
 public:
  /// Generates the world, plans the route and runs every sensor model.
  /// Throws std::invalid_argument for bad options.
  FilterFeed(const Scenario& scenario, uint64_t seed, const FilterFeedOptions& options = {});
  ~FilterFeed();
  FilterFeed(FilterFeed&&) noexcept;
  FilterFeed& operator=(FilterFeed&&) noexcept;

  /// Every input in merge order (non-decreasing stamps).
  const std::vector<estimator::EskfInput>& inputs() const { return inputs_; }
  /// Truth at every IMU sample (with the IMU's true biases), in order.
  const std::vector<TruthSample>& imu_truth() const { return imu_truth_; }
  /// Truth at every camera trigger (capture time), in order.
  const std::vector<TruthSample>& trigger_truth() const { return trigger_truth_; }
  /// The wheel model's truth at every SYNC (emitted or not).
  const std::vector<WheelSyncState>& wheel_truth() const { return wheel_truth_; }
  /// Exact truth at any time (the trajectory evaluated at t; biases zero).
  TruthSample TruthAt(Time t) const;

  const Scenario& scenario() const { return scenario_; }
  const RoverTrajectory& trajectory() const { return *trajectory_; }
  const WheelOdometryModelOptions& wheel_options() const { return wheel_options_; }
  const FilterFeedOptions& options() const { return options_; }
  uint64_t seed() const { return seed_; }
  Time start() const { return start_; }
  Time end() const { return end_; }
  const FilterFeedCounts& counts() const { return counts_; }
  /// Horizontal distance driven over the feed (from the IMU-rate truth).
  double distance_m() const { return distance_m_; }

 private:
  Scenario scenario_;
  uint64_t seed_ = 0;
  FilterFeedOptions options_;
  std::unique_ptr<RoverTrajectory> trajectory_;
  WheelOdometryModelOptions wheel_options_;
  Time start_;
  Time end_;
  std::vector<estimator::EskfInput> inputs_;
  std::vector<TruthSample> imu_truth_;
  std::vector<TruthSample> trigger_truth_;
  std::vector<WheelSyncState> wheel_truth_;
  FilterFeedCounts counts_;
  double distance_m_ = 0.0;
};

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_ESTIMATOR_FEED_FILTER_FEED_H_
