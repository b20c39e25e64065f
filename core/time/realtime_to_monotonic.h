#ifndef ROVER_CORE_TIME_REALTIME_TO_MONOTONIC_H_
#define ROVER_CORE_TIME_REALTIME_TO_MONOTONIC_H_

// Moves stamps the kernel or a library takes on CLOCK_REALTIME (SocketCAN
// receive stamps, Aravis's buffer system timestamps) onto CLOCK_MONOTONIC,
// where every stamp of the system lives.
//
// The realtime - monotonic offset is read as monotonic, realtime, monotonic
// and kept only when that bracket is tight: a thread preempted between two
// clock reads (any guest under emulation, any busy board) would otherwise
// shift stamps by milliseconds. A wide bracket keeps the previous offset.
// The offset itself changes only when the realtime clock is stepped or
// slewed, so it is re-read at most every `refresh_period`. No allocation, no
// locks: one instance per thread.

#include <cstdint>

#include "core/time/time.h"

namespace rover {

class RealtimeToMonotonic {
 public:
  /// `tight_bracket`: the widest monotonic span around the realtime read
  /// that is trusted; `refresh_period`: how often the offset is re-read.
  explicit RealtimeToMonotonic(Duration tight_bracket = Duration::Microseconds(50),
                               Duration refresh_period = Duration::Milliseconds(100))
      : tight_bracket_(tight_bracket), refresh_period_(refresh_period) {}

  /// The monotonic time of `realtime_ns` (ns since the epoch on
  /// CLOCK_REALTIME), with the offset refreshed first if it is due.
  Time ToMonotonic(int64_t realtime_ns);

  /// realtime - monotonic as last read (0 before the first conversion).
  Duration offset() const { return Duration::Nanoseconds(real_minus_mono_ns_); }

 private:
  void Refresh();

  Duration tight_bracket_;
  Duration refresh_period_;
  int64_t real_minus_mono_ns_ = 0;
  Time read_at_;
  bool valid_ = false;
};

}  // namespace rover

#endif  // ROVER_CORE_TIME_REALTIME_TO_MONOTONIC_H_
