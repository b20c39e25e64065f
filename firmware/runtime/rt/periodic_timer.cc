#include "firmware/runtime/rt/periodic_timer.h"

#include <cerrno>
#include <ctime>
#include <stdexcept>
#include <string>

#include "core/time/posix_time.h"

namespace rover::runtime {
namespace {

class MonotonicClockImpl final : public PeriodicTimer::Clock {
 public:
  Time Now() override { return Time::Now(); }

  void SleepUntil(Time deadline) override { rover::SleepUntil(deadline); }
};

}  // namespace

PeriodicTimer::Clock& PeriodicTimer::MonotonicClock() {
  static MonotonicClockImpl clock;
  return clock;
}

PeriodicTimer::PeriodicTimer(Duration period, Time first_deadline, Clock& clock)
    : period_(period), first_deadline_(first_deadline), clock_(&clock) {
  if (period <= Duration::Zero()) {
    throw std::invalid_argument("PeriodicTimer: expected a positive period, found " +
                                std::to_string(period.nanoseconds()) + " ns");
  }
}

PeriodicTimer::PeriodicTimer(Duration period, Clock& clock)
    : PeriodicTimer(period, clock.Now() + period, clock) {}

PeriodicTimer::Tick PeriodicTimer::WaitNext() {
  Tick tick;
  Time deadline = next_deadline();
  const Time now = clock_->Now();
  if (now < deadline) {
    clock_->SleepUntil(deadline);
    tick.index = next_index_;
    tick.woke = clock_->Now();
  } else {
    // Late: serve the latest slot whose deadline has passed, skip the others.
    const int64_t late_slots = (now - deadline).nanoseconds() / period_.nanoseconds();
    tick.index = next_index_ + late_slots;
    tick.missed_periods = static_cast<uint64_t>(late_slots);
    deadline = deadline + period_ * late_slots;
    tick.woke = now;
    tick.slept = false;
  }
  tick.deadline = deadline;
  next_index_ = tick.index + 1;
  ++ticks_;
  missed_periods_ += tick.missed_periods;
  return tick;
}

}  // namespace rover::runtime
