#ifndef ROVER_DRIVERS_IMU_CLOCK_OFFSET_TRACKER_H_
#define ROVER_DRIVERS_IMU_CLOCK_OFFSET_TRACKER_H_

#include <cstdint>

#include "core/time/time.h"

namespace rover::drivers {

struct ClockOffsetTrackerOptions {
  /// Largest rate (parts per million) at which the device clock may run
  /// slow against CLOCK_MONOTONIC and still be followed without lag. The
  /// envelope rises at this rate between packets (see ClockOffsetTracker).
  /// Crystal oscillators stay within +-50 ppm; the default leaves margin.
  double max_drift_ppm = 200.0;

  /// Throws std::invalid_argument unless max_drift_ppm is in [0, 10000].
  void Validate() const;
};

/// Maps a device clock (an IMU's own sample time) onto CLOCK_MONOTONIC from
/// the host receive times of its packets.
///
/// A packet sampled at device time d arrives at host time r = d + o + l,
/// where o is the clock offset and l >= 0 the transport delay (UART
/// transmission, USB polling, scheduling), which jitters by up to
/// milliseconds. Stamping with r would put that jitter into every sample;
/// stamping with d + o would not, so the tracker estimates o as the lower
/// envelope of the candidates c = r - d: each candidate lies at or above
/// o + l_min, and the packets that travelled fastest touch it.
///
/// The envelope e drops at once to any candidate below it and otherwise
/// rises by max_drift_ppm times the device time elapsed since the previous
/// packet: e_k = min(c_k, e_{k-1} + rate * (d_k - d_{k-1})). The rise lets it
/// follow a device clock that runs slow (offsets that grow), the drop one
/// that runs fast. Compared with the minimum over a sliding window, it needs
/// no history (O(1), nothing stored), follows drift without a window-length
/// lag, and never steps by more than the rise between two packets, while a
/// late packet never raises it at all. The stamp is d + e: it lies within
/// l_min plus the envelope's sawtooth (rate times the time between fast
/// packets, microseconds) of the true sample time, and never after the
/// receive time. Only the constant part l_min of the delay remains; a caller
/// that knows it subtracts it.
///
/// Update() never allocates, throws or locks.
class ClockOffsetTracker {
 public:
  explicit ClockOffsetTracker(const ClockOffsetTrackerOptions& options = {});

  /// Adds one packet: `device_ns`, its device sample time in nanoseconds
  /// (any epoch, must not decrease between calls), and `receive_time`, when
  /// the host had it. Returns its sample time on CLOCK_MONOTONIC. A device
  /// time earlier than the previous one means the device clock restarted:
  /// the tracker starts over from this packet (counted in resets()).
  Time Update(int64_t device_ns, Time receive_time);

  /// Forgets the estimate; the next Update starts over.
  void Reset();

  bool initialized() const { return initialized_; }
  /// Current envelope e (receive minus device time), nanoseconds.
  double offset_ns() const { return offset_ns_; }
  /// Times the device clock went backwards.
  uint64_t resets() const { return resets_; }

 private:
  double rise_per_ns_;
  bool initialized_ = false;
  int64_t last_device_ns_ = 0;
  double offset_ns_ = 0.0;
  uint64_t resets_ = 0;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_IMU_CLOCK_OFFSET_TRACKER_H_
