#ifndef ROVER_ESTIMATOR_ESKF_LOCAL_REFERENCE_FILTER_H_
#define ROVER_ESTIMATOR_ESKF_LOCAL_REFERENCE_FILTER_H_

// The local reference filter: an error-state EKF over (p, v, q, b_a, b_g) in
// a gravity-aligned local frame, with stochastic clones at camera capture
// times, delayed relative-pose updates, wheel odometry, zero-velocity updates
// and frame-of-reference switches (thesis section 4.1; math in README.md).
//
// Real-time contract: the constructor allocates everything; after that no
// call allocates, locks or blocks, and the cost per call is bounded.
// Determinism: outputs are a pure function of the order and content of the
// calls (no clocks, no threads, no randomness).

#include <array>
#include <limits>
#include <memory>

#include "estimator/eskf/eskf_health.h"
#include "estimator/eskf/eskf_input.h"
#include "estimator/eskf/eskf_options.h"
#include "estimator/eskf/eskf_output.h"
#include "estimator/eskf/init/standstill_detector.h"
#include "estimator/eskf/propagator/imu_propagator.h"
#include "estimator/eskf/state/filter_state.h"
#include "estimator/eskf/update/relative_pose_updater.h"
#include "estimator/eskf/update/wheel_odometry_updater.h"
#include "estimator/eskf/update/zero_velocity_updater.h"

namespace rover::estimator {

class LocalReferenceFilter {
 public:
  /// `sink` receives every output; it must outlive the filter. It may be
  /// null (then outputs are only available through state()).
  LocalReferenceFilter(const EskfOptions& options, EskfOutputSink* sink);

  /// Dispatches any input to the matching Add* call.
  void Process(const EskfInput& input);

  /// Propagates to the sample (cloning at pending triggers on the way) and
  /// emits one EskfOutput. Before initialisation, feeds the standstill
  /// detector and initialises once the rover has stood still for
  /// init.window_s.
  void AddImu(const ImuMeasurement& m);
  /// Clones the pose at m.stamp: now if the stamp is at most
  /// clones.max_trigger_lateness_s old, else when the IMU reaches it.
  void AddCloneTrigger(const CloneTrigger& m);
  /// Delayed relative pose between two clones.
  void AddRelativePose(const RelativePoseMeasurement& m);
  /// Wheel rates; averaged and applied once per wheels.update_period_s.
  void AddWheelSpeeds(const WheelSpeedMeasurement& m);
  /// Switches the frame of reference now; emits a FrameSwitchRecord.
  void RequestFrameSwitch(const FrameSwitchRequest& m);
  /// Emits a PoseReport of the current pose.
  void RequestPoseReport(const PoseReportRequest& m);

  bool initialised() const { return initialised_; }
  const FilterState& state() const { return *state_; }
  const EskfHealth& health() const { return health_; }
  /// The latest output (valid once initialised).
  const EskfOutput& output() const { return output_; }
  const EskfOptions& options() const { return options_; }

 private:
  void Initialise(const ImuMeasurement& m);
  void PropagateTo(const ImuMeasurement& m);
  void CloneNow();
  void CloneLate(Time stamp);
  bool MakeRoomForClone();
  void AfterRelativePose(int ib, const RelativePoseMeasurement& m);
  void MaybeZeroVelocityUpdate();
  void ApplyWheelAverage();
  void EmitState();
  void Reject(Time stamp, InputKind kind, RejectReason reason, double d2 = 0.0, double gate = 0.0);
  void Accept(InputKind kind) { ++health_.accepted[static_cast<size_t>(kind)]; }
  uint32_t StatusFlags() const;
  bool Recent(Time event) const;

  EskfOptions options_;
  EskfOutputSink* sink_;
  ImuPropagator propagator_;
  RelativePoseUpdater relative_pose_updater_;
  WheelOdometryUpdater wheel_updater_;
  ZeroVelocityUpdater zupt_updater_;
  StandstillDetector init_detector_;
  StandstillDetector zupt_detector_;
  // Large (fixed-size covariance, ~33 KB): one allocation, in the constructor.
  std::unique_ptr<FilterState> state_;

  bool initialised_ = false;
  bool have_last_imu_ = false;
  ImuMeasurement last_imu_;
  Time last_trigger_stamp_ = kNever;
  static constexpr int kMaxPendingTriggers = 8;
  std::array<Time, kMaxPendingTriggers> pending_triggers_{};
  int pending_trigger_count_ = 0;

  // Wheel averaging.
  std::array<double, 4> wheel_sum_{};
  int wheel_count_ = 0;
  Time wheel_window_start_;
  Time last_wheel_stamp_ = kNever;
  Time last_wheel_motion_ = kNever;  ///< latest reading with a turning wheel

  // Health bookkeeping.
  static constexpr Time kNever = Time::FromNanoseconds(std::numeric_limits<int64_t>::min() / 2);
  Time last_gap_ = kNever;
  Time last_invalid_imu_ = kNever;
  Time last_numerical_ = kNever;
  Time last_aiding_ = kNever;
  Time last_zupt_ = kNever;
  bool standing_ = false;
  Duration recovery_;
  Duration max_gap_;

  EskfHealth health_;
  EskfOutput output_;
};

}  // namespace rover::estimator

#endif  // ROVER_ESTIMATOR_ESKF_LOCAL_REFERENCE_FILTER_H_
