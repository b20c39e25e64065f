#include "firmware/runtime/log_service/rate_limiter.h"

#include <algorithm>

namespace rover::runtime {

RateLimiter::RateLimiter(uint64_t rate_bytes_per_s) : rate_bytes_per_s_(rate_bytes_per_s) {}

bool RateLimiter::Acquire(uint64_t bytes) {
  std::unique_lock lock(mutex_);
  if (cancelled_) return false;
  if (rate_bytes_per_s_ == 0) return true;
  const Clock::time_point start = std::max(Clock::now(), next_);
  const auto cost_ns = static_cast<int64_t>(static_cast<double>(bytes) * 1e9 /
                                            static_cast<double>(rate_bytes_per_s_));
  next_ = start + std::chrono::nanoseconds(cost_ns);
  cancelled_cv_.wait_until(lock, start, [&] { return cancelled_; });
  return !cancelled_;
}

void RateLimiter::Cancel() {
  {
    std::lock_guard lock(mutex_);
    cancelled_ = true;
  }
  cancelled_cv_.notify_all();
}

}  // namespace rover::runtime
