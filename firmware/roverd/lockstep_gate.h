#ifndef ROVER_FIRMWARE_ROVERD_LOCKSTEP_GATE_H_
#define ROVER_FIRMWARE_ROVERD_LOCKSTEP_GATE_H_

// Couples roverd's threads when the sensors run faster than real time
// (simulation in lockstep, tests): the IMU thread steps the filter to time t
// only when every input due by t has been handed over, i.e.
//   - the camera has handed over every frame captured at or before t (each
//     frame's clone trigger is an input at its capture time): it is past t,
//     or holds a frame captured after t;
//   - the VO has finished every frame captured at or before t - vo_latency
//     (its result is delivered at capture + vo_latency);
//   - the CAN thread has handed over a frame stamped at or after t, or holds
//     one stamped after t.
// The camera and CAN threads in turn stay at most `lead` ahead of the time
// the IMU thread is stepping to, so the hand-over rings never overflow. The
// VO thread starts a frame only once the IMU thread has stepped every sample
// up to its capture time, so what it reads of the filter (whether it has
// initialised) is that of the capture time, not of how far the IMU thread
// happened to run: the run is then a function of its inputs alone. With real sensors none of
// this is used: each thread runs on its own clock and the IMU thread never waits.

#include <condition_variable>
#include <deque>
#include <mutex>

#include "core/time/time.h"

namespace rover::roverd {

class LockstepGate {
 public:
  LockstepGate(bool camera, bool can, Duration vo_latency, Duration lead)
      : camera_(camera), can_(can), vo_latency_(vo_latency), lead_(lead) {}

  /// IMU thread: announces that it steps to `t` next and blocks until
  /// everything due by `t` is handed over (or Stop()).
  void WaitBeforeImu(Time t);
  /// Camera thread: a frame captured at `capture` arrived; blocks while it is
  /// more than `lead` ahead of the time the IMU thread is stepping to.
  void FrameArrived(Time capture);
  /// Camera thread: a frame captured at `capture` goes to the VO.
  void FrameQueued(Time capture);
  /// Camera thread: a frame captured at `capture` is dropped (no VO result).
  void FrameSkipped(Time capture);
  /// VO thread: the oldest queued frame is done (its result handed over).
  void FrameDone();
  /// VO thread: blocks until the IMU thread has stepped every sample up to
  /// `capture` (it has announced a later sample, or ended).
  void WaitForImuAt(Time capture);
  /// IMU thread: the sample at `t` is stepped and its state published.
  void ImuStepped(Time t);
  /// IMU thread: no more samples.
  void ImuEnded();
  void CameraEnded();
  /// CAN thread: a frame stamped `stamp` arrived; blocks while it is more
  /// than `lead` ahead of the time the IMU thread is stepping to.
  void CanFrameArrived(Time stamp);
  /// CAN thread: that frame has been decoded and handed over.
  void CanFrameDone(Time stamp);
  void CanEnded();
  /// Releases every waiter for good.
  void Stop();

 private:
  bool ImuMayStep(Time t) const;

  const bool camera_;
  const bool can_;
  const Duration vo_latency_;
  const Duration lead_;
  std::mutex mutex_;
  std::condition_variable changed_;
  Time imu_target_ = Time::FromNanoseconds(INT64_MIN / 2);  // what the IMU steps to next
  Time imu_done_ = Time::FromNanoseconds(INT64_MIN / 2);    // the last sample stepped
  bool imu_ended_ = false;
  std::deque<Time> frames_in_flight_;
  Time camera_through_ = Time::FromNanoseconds(INT64_MIN / 2);
  bool camera_holding_ = false;  // a received frame waits to be handed over
  Time camera_held_stamp_;
  bool camera_ended_ = false;
  Time can_through_ = Time::FromNanoseconds(INT64_MIN / 2);
  bool can_holding_ = false;  // a received frame waits to be handed over
  Time can_held_stamp_;
  bool can_ended_ = false;
  bool stopped_ = false;
};

}  // namespace rover::roverd

#endif  // ROVER_FIRMWARE_ROVERD_LOCKSTEP_GATE_H_
