#include "firmware/runtime/health/systemd_notifier.h"

#include <systemd/sd-daemon.h>

#include <cstdint>
#include <cstdlib>
#include <string>

namespace rover::runtime {

SystemdNotifier SystemdNotifier::FromEnvironment() {
  const char* socket = std::getenv("NOTIFY_SOCKET");
  const bool enabled = socket != nullptr && socket[0] != '\0';
  std::optional<Duration> watchdog;
  uint64_t usec = 0;
  // > 0: enabled for this process; 0: not enabled (or WATCHDOG_PID names
  // another process); < 0: a malformed variable, treated as no watchdog.
  if (sd_watchdog_enabled(/*unset_environment=*/0, &usec) > 0 && usec > 0) {
    watchdog = Duration::Microseconds(static_cast<int64_t>(usec));
  }
  return SystemdNotifier(enabled, watchdog);
}

std::optional<Duration> SystemdNotifier::watchdog_ping_period() const {
  if (!watchdog_interval_) return std::nullopt;
  return *watchdog_interval_ / 2;
}

bool SystemdNotifier::Ready() const noexcept { return Send("READY=1"); }

bool SystemdNotifier::Watchdog() const noexcept { return Send("WATCHDOG=1"); }

bool SystemdNotifier::Stopping() const noexcept { return Send("STOPPING=1"); }

bool SystemdNotifier::Status(std::string_view status) const noexcept {
  if (!enabled_) return false;
  try {
    std::string message = "STATUS=";
    message.reserve(message.size() + status.size());
    for (const char c : status) {
      message.push_back(c == '\n' || c == '\r' || c == '\0' ? ' ' : c);
    }
    return Send(message.c_str());
  } catch (...) {  // std::bad_alloc: no status this time, the service goes on.
    return false;
  }
}

bool SystemdNotifier::Send(const char* state) const noexcept {
  if (!enabled_) return false;
  // > 0: sent; 0: NOTIFY_SOCKET vanished from the environment; < 0: -errno.
  return sd_notify(/*unset_environment=*/0, state) > 0;
}

}  // namespace rover::runtime
