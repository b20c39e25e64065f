#include "drivers/imu/clock_offset_tracker.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace rover::drivers {

void ClockOffsetTrackerOptions::Validate() const {
  if (!(max_drift_ppm >= 0.0 && max_drift_ppm <= 10'000.0)) {
    throw std::invalid_argument(
        "ClockOffsetTrackerOptions: max_drift_ppm must be in [0, 10000], found " +
        std::to_string(max_drift_ppm));
  }
}

ClockOffsetTracker::ClockOffsetTracker(const ClockOffsetTrackerOptions& options)
    : rise_per_ns_((options.Validate(), options.max_drift_ppm * 1e-6)) {}

void ClockOffsetTracker::Reset() { initialized_ = false; }

Time ClockOffsetTracker::Update(int64_t device_ns, Time receive_time) {
  const double candidate =
      static_cast<double>(receive_time.nanoseconds()) - static_cast<double>(device_ns);
  if (initialized_ && device_ns < last_device_ns_) {
    ++resets_;
    initialized_ = false;
  }
  if (!initialized_) {
    offset_ns_ = candidate;
    initialized_ = true;
  } else {
    const double risen =
        offset_ns_ + rise_per_ns_ * static_cast<double>(device_ns - last_device_ns_);
    offset_ns_ = candidate < risen ? candidate : risen;
  }
  last_device_ns_ = device_ns;
  return Time::FromNanoseconds(device_ns + std::llround(offset_ns_));
}

}  // namespace rover::drivers
