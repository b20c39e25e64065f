#ifndef ROVER_FIRMWARE_RUNTIME_LOG_SERVICE_RATE_LIMITER_H_
#define ROVER_FIRMWARE_RUNTIME_LOG_SERVICE_RATE_LIMITER_H_

// Paces the log service's transfers so that together they stay under a
// bandwidth limit (a virtual clock: each grant moves the next allowed send
// time by bytes / rate), leaving link and disk to the rest of the rover.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>

namespace rover::runtime {

class RateLimiter {
 public:
  /// `rate_bytes_per_s` 0 means unlimited (Acquire() never waits).
  explicit RateLimiter(uint64_t rate_bytes_per_s);

  /// Waits until `bytes` more may be sent without exceeding the rate, summed
  /// over every caller. Returns false at once, or as soon as Cancel() is
  /// called while waiting.
  bool Acquire(uint64_t bytes);

  /// Wakes every waiter; Acquire() returns false from now on.
  void Cancel();

  /// The limit given at construction; 0 means unlimited.
  uint64_t rate_bytes_per_s() const { return rate_bytes_per_s_; }

 private:
  using Clock = std::chrono::steady_clock;

  const uint64_t rate_bytes_per_s_;
  std::mutex mutex_;
  std::condition_variable cancelled_cv_;
  bool cancelled_ = false;    // guarded by mutex_
  Clock::time_point next_{};  // guarded by mutex_: earliest start of the next grant
};

}  // namespace rover::runtime

#endif  // ROVER_FIRMWARE_RUNTIME_LOG_SERVICE_RATE_LIMITER_H_
