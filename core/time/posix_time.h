#ifndef ROVER_CORE_TIME_POSIX_TIME_H_
#define ROVER_CORE_TIME_POSIX_TIME_H_

// Time and Duration at the POSIX boundary (ppoll, nanosleep,
// clock_nanosleep): one conversion, and sleeps that resume after a signal.
// No allocation; safe on real-time threads.

#include <time.h>

#include "core/time/time.h"

namespace rover {

/// A span as a relative timespec; negative spans become zero.
timespec ToTimespec(Duration d);
/// A point on CLOCK_MONOTONIC as the absolute timespec of clock_nanosleep.
timespec ToTimespec(Time t);
/// Sleeps until `t` on CLOCK_MONOTONIC (absolute deadline: a late wake-up
/// does not shift the next one); returns at once if `t` has passed.
void SleepUntil(Time t);
/// Sleeps for `d` (nothing for d <= 0), resuming after signals.
void SleepFor(Duration d);

}  // namespace rover

#endif  // ROVER_CORE_TIME_POSIX_TIME_H_
