#ifndef ROVER_FIRMWARE_ROVERD_ESTIMATOR_LOOP_H_
#define ROVER_FIRMWARE_ROVERD_ESTIMATOR_LOOP_H_

// The estimator as roverd's IMU thread runs it. Other threads hand their
// measurements over through one SPSC ring each (VO relative poses, wheel
// speeds, camera clone triggers, requests from mapd); at every IMU sample the
// IMU thread drains the rings, merges what arrived in time-stamp order (at
// equal stamps: clone triggers, wheel speeds, relative poses, requests),
// feeds every input whose stamp is not after the sample to the filter, then
// the sample itself.
//
// Every input is logged exactly as the filter saw it, with its position in
// the filter's input order (`sequence`), and every output with the sequence
// of the input that produced it, so that `rover replay` can feed the logged
// inputs to a fresh filter and check that each output is bit-identical.
//
// Real-time rules: after construction, Step() and the Push*() calls neither
// allocate, lock nor block (the log channels and rings are wait-free). A full
// ring refuses the push and counts a drop; a full log ring drops the record
// and the flight log counts it (replay then reports the gap).

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>

#include "core/log/flight/flight_log.h"
#include "core/log/msgs/estimator_msgs.h"
#include "core/log/msgs/geometry_msgs.h"
#include "core/log/msgs/nav_msgs.h"
#include "core/ring/spsc_ring.h"
#include "estimator/eskf/eskf_input.h"
#include "estimator/eskf/eskf_options.h"
#include "estimator/eskf/eskf_output.h"
#include "estimator/eskf/local_reference_filter.h"
#include "estimator/feed/input_merger.h"
#include "estimator/io/estimator_log_records.h"

namespace rover::roverd {

using estimator::io::kEventInputTopic;
using estimator::io::kFrameSwitchRecordTopic;
using estimator::io::kFrameSwitchTopic;
using estimator::io::kImuInputTopic;
using estimator::io::kOdometryTopic;
using estimator::io::kOptionsMetadata;
using estimator::io::kRelativePoseInputTopic;
using estimator::io::kStateTopic;
using estimator::io::kWheelSpeedsInputTopic;

/// The flight-log channels of the estimator (created before the log starts).
struct EstimatorLogChannels {
  log::LogChannel<log::rover_msgs::EstimatorImu>* imu = nullptr;
  log::LogChannel<log::rover_msgs::EstimatorEvent>* events = nullptr;
  log::LogChannel<log::rover_msgs::EstimatorRelativePose>* relative_poses = nullptr;
  log::LogChannel<log::rover_msgs::EstimatorWheelSpeeds>* wheel_speeds = nullptr;
  log::LogChannel<log::rover_msgs::EstimatorState, 2048, 2048>* states = nullptr;
  log::LogChannel<log::rover_msgs::EstimatorFrameSwitch>* frame_switches = nullptr;
  log::LogChannel<log::nav_msgs::Odometry>* odometry = nullptr;
  log::LogChannel<log::geometry_msgs::TransformStamped>* frame_switch_transforms = nullptr;

  /// Registers every channel and writes the options metadata. Call between
  /// FlightLog::Open() and Start().
  static EstimatorLogChannels Add(log::FlightLog* log, const estimator::EskfOptions& options);
};

/// Drops and counts of the hand-over, readable from any thread.
struct EstimatorLoopStats {
  uint64_t inputs = 0;        ///< given to the filter (the next sequence number)
  uint64_t states = 0;        ///< outputs after IMU samples
  uint64_t ring_drops = 0;    ///< pushes refused because a ring was full
  uint64_t pending_full = 0;  ///< Step() left inputs in a ring (merge buffer full)
  uint64_t late_inputs = 0;   ///< stamped before the previous IMU sample when merged
};

/// Called on the IMU thread after each state output (e.g. to publish it).
class EstimatorListener {
 public:
  virtual ~EstimatorListener() = default;
  virtual void OnState(const estimator::EskfOutput& output) = 0;
  virtual void OnFrameSwitch(const estimator::FrameSwitchRecord& record) = 0;
};

class EstimatorLoop final : private estimator::EskfOutputSink {
 public:
  static constexpr std::size_t kRingSlots = 256;
  static constexpr std::size_t kMergeSlots = 64;

  /// `channels` may hold null channels (not logged); `listener` may be null.
  /// Allocates everything the loop will need. `lockstep`: the inputs come
  /// faster than real time (simulation, tests), so Step() waits for the log
  /// writer whenever a log ring is half full instead of dropping records;
  /// never use it on a real-time thread.
  EstimatorLoop(const estimator::EskfOptions& options, const EstimatorLogChannels& channels,
                EstimatorListener* listener = nullptr, bool lockstep = false);
  EstimatorLoop(const EstimatorLoop&) = delete;
  EstimatorLoop& operator=(const EstimatorLoop&) = delete;

  // Producers, one thread each. False (and a counted drop) when the ring is full.
  bool PushRelativePose(const estimator::RelativePoseMeasurement& m);   ///< VO thread
  bool PushWheelSpeeds(const estimator::WheelSpeedMeasurement& m);      ///< CAN thread
  bool PushCloneTrigger(const estimator::CloneTrigger& m);              ///< camera thread
  bool PushFrameSwitchRequest(const estimator::FrameSwitchRequest& m);  ///< request thread

  /// IMU thread: merges the handed-over inputs due by `imu.stamp`, then the sample.
  void Step(const estimator::ImuMeasurement& imu);

  /// IMU thread, at the end of a run: feeds every input still waiting,
  /// whatever its stamp (they would otherwise be lost from the log).
  void Drain();

  const estimator::LocalReferenceFilter& filter() const { return filter_; }
  /// Snapshot of the counters (any thread).
  EstimatorLoopStats stats() const;

 private:
  void Collect();
  void WaitForLogRoom() const;
  void Feed(const estimator::EskfInput& input);
  void LogInput(const estimator::EskfInput& input, uint64_t sequence);
  // EskfOutputSink, called by the filter on this thread.
  void OnState(const estimator::EskfOutput& output) override;
  void OnFrameSwitch(const estimator::FrameSwitchRecord& record) override;
  void OnPoseReport(const estimator::PoseReport& report) override;
  void OnReject(const estimator::RejectRecord& record) override;

  estimator::LocalReferenceFilter filter_;
  EstimatorLogChannels channels_;
  EstimatorListener* listener_;
  bool lockstep_;

  SpscRing<estimator::RelativePoseMeasurement, kRingSlots> relative_poses_;
  SpscRing<estimator::WheelSpeedMeasurement, kRingSlots> wheel_speeds_;
  SpscRing<estimator::CloneTrigger, kRingSlots> clone_triggers_;
  SpscRing<estimator::FrameSwitchRequest, kRingSlots> requests_;

  estimator::InputMerger<kMergeSlots> merger_;
  uint64_t current_sequence_ = 0;  ///< of the input being fed (outputs carry it)

  std::atomic<uint64_t> inputs_{0};
  std::atomic<uint64_t> states_{0};
  std::atomic<uint64_t> ring_drops_{0};
  std::atomic<uint64_t> pending_full_{0};
  std::atomic<uint64_t> late_inputs_{0};
};

}  // namespace rover::roverd

#endif  // ROVER_FIRMWARE_ROVERD_ESTIMATOR_LOOP_H_
