#include "firmware/roverd/lockstep_gate.h"

namespace rover::roverd {

bool LockstepGate::ImuMayStep(Time t) const {
  if (stopped_) return true;
  // Every frame captured by t has had its clone trigger handed over: the
  // camera is past t, or holds a frame captured after t. (This also means
  // no frame the VO owes a result for by t can still come.)
  const bool camera_ok = !camera_ || camera_ended_ || camera_through_ >= t ||
                         (camera_holding_ && camera_held_stamp_ > t);
  const Time due = t - vo_latency_;
  const bool vo_ok = frames_in_flight_.empty() || frames_in_flight_.front() > due;
  const bool can_ok =
      !can_ || can_ended_ || can_through_ >= t || (can_holding_ && can_held_stamp_ > t);
  return camera_ok && vo_ok && can_ok;
}

void LockstepGate::WaitBeforeImu(Time t) {
  std::unique_lock lock(mutex_);
  imu_target_ = t;
  changed_.notify_all();  // producers held back by the lead may go on
  changed_.wait(lock, [&] { return ImuMayStep(t); });
}

void LockstepGate::FrameArrived(Time capture) {
  std::unique_lock lock(mutex_);
  camera_holding_ = true;
  camera_held_stamp_ = capture;
  changed_.notify_all();
  changed_.wait(lock, [&] { return stopped_ || capture <= imu_target_ + lead_; });
}

void LockstepGate::FrameQueued(Time capture) {
  {
    const std::lock_guard lock(mutex_);
    frames_in_flight_.push_back(capture);
    camera_holding_ = false;
    camera_through_ = capture;
  }
  changed_.notify_all();
}

void LockstepGate::FrameSkipped(Time capture) {
  {
    const std::lock_guard lock(mutex_);
    camera_holding_ = false;
    camera_through_ = capture;
  }
  changed_.notify_all();
}

void LockstepGate::FrameDone() {
  {
    const std::lock_guard lock(mutex_);
    if (!frames_in_flight_.empty()) frames_in_flight_.pop_front();
  }
  changed_.notify_all();
}

void LockstepGate::WaitForImuAt(Time capture) {
  std::unique_lock lock(mutex_);
  // The IMU thread announces its next sample only once the previous one is
  // stepped, so a target after the capture means every sample up to the
  // capture is done. Waiting for more could deadlock: the IMU thread may be
  // waiting for the camera, and the camera for a slot this frame holds.
  changed_.wait(lock, [&] {
    return stopped_ || imu_ended_ || imu_done_ >= capture || imu_target_ > capture;
  });
}

void LockstepGate::ImuStepped(Time t) {
  {
    const std::lock_guard lock(mutex_);
    imu_done_ = t;
  }
  changed_.notify_all();
}

void LockstepGate::ImuEnded() {
  {
    const std::lock_guard lock(mutex_);
    imu_ended_ = true;
  }
  changed_.notify_all();
}

void LockstepGate::CameraEnded() {
  {
    const std::lock_guard lock(mutex_);
    camera_ended_ = true;
  }
  changed_.notify_all();
}

void LockstepGate::CanFrameArrived(Time stamp) {
  std::unique_lock lock(mutex_);
  can_holding_ = true;
  can_held_stamp_ = stamp;
  changed_.notify_all();
  changed_.wait(lock, [&] { return stopped_ || stamp <= imu_target_ + lead_; });
}

void LockstepGate::CanFrameDone(Time stamp) {
  {
    const std::lock_guard lock(mutex_);
    can_holding_ = false;
    can_through_ = stamp;
  }
  changed_.notify_all();
}

void LockstepGate::CanEnded() {
  {
    const std::lock_guard lock(mutex_);
    can_ended_ = true;
  }
  changed_.notify_all();
}

void LockstepGate::Stop() {
  {
    const std::lock_guard lock(mutex_);
    stopped_ = true;
  }
  changed_.notify_all();
}

}  // namespace rover::roverd
