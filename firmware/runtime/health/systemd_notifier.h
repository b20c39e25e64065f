#ifndef ROVER_FIRMWARE_RUNTIME_HEALTH_SYSTEMD_NOTIFIER_H_
#define ROVER_FIRMWARE_RUNTIME_HEALTH_SYSTEMD_NOTIFIER_H_

// The firmware's side of systemd's service notification protocol
// (sd_notify(3)): readiness, watchdog keep-alives, a one-line status and
// shutdown, sent as datagrams to the socket named by $NOTIFY_SOCKET.
//
// Under systemd (a Type=notify unit, optionally with WatchdogSec=) the
// manager sets NOTIFY_SOCKET, WATCHDOG_USEC and WATCHDOG_PID in the
// service's environment. Everywhere else (a shell, the simulator, the tests)
// NOTIFY_SOCKET is unset and every call is a cheap no-op, so the firmware
// calls the notifier unconditionally instead of asking where it runs.
//
// The environment is read once, by FromEnvironment(); sending re-reads
// NOTIFY_SOCKET inside libsystemd. Every sending function is noexcept and
// reports success as a bool: a lost keep-alive must never take the health
// thread down (systemd restarts the service if keep-alives stop anyway).

#include <optional>
#include <string_view>

#include "core/time/time.h"

namespace rover::runtime {

/// Sends sd_notify(3) messages when running under systemd, does nothing
/// otherwise. Cheap to copy; safe to call from any one thread at a time.
class SystemdNotifier {
 public:
  /// A disabled notifier: every send returns false, no watchdog.
  SystemdNotifier() = default;

  /// Reads the calling process's environment: enabled if NOTIFY_SOCKET is
  /// set and non-empty; the watchdog interval from WATCHDOG_USEC when
  /// WATCHDOG_PID is unset or names this process (sd_watchdog_enabled(3)).
  /// Leaves the environment unchanged (child processes inherit it).
  static SystemdNotifier FromEnvironment();

  /// True if a notification socket was configured (we run under systemd).
  bool enabled() const { return enabled_; }

  /// The service's watchdog timeout (WatchdogSec=), or nullopt if systemd
  /// does not watch this process. Keep-alives must arrive more often than
  /// this; see watchdog_ping_period().
  std::optional<Duration> watchdog_interval() const { return watchdog_interval_; }

  /// Half the watchdog interval, the keep-alive period sd_watchdog_enabled(3)
  /// recommends so that one late ping does not trigger a restart; nullopt
  /// without a watchdog.
  std::optional<Duration> watchdog_ping_period() const;

  /// Sends "READY=1": start-up is complete (a Type=notify unit counts as
  /// started from here). Returns true if the datagram was sent; false if
  /// disabled or sending failed. Never throws.
  bool Ready() const noexcept;

  /// Sends "WATCHDOG=1", the watchdog keep-alive. Returns true if sent;
  /// false if disabled or sending failed. Never throws.
  bool Watchdog() const noexcept;

  /// Sends "STATUS=<status>", the line `systemctl status` shows. Line
  /// breaks and NUL bytes become spaces: a line break would end the
  /// assignment and let the rest be read as another one (e.g. "READY=1").
  /// Returns true if sent; false if disabled, out of memory or sending
  /// failed. Never throws.
  bool Status(std::string_view status) const noexcept;

  /// Sends "STOPPING=1": the service is shutting down (systemd then stops
  /// expecting keep-alives). Returns true if sent; false if disabled or
  /// sending failed. Never throws.
  bool Stopping() const noexcept;

 private:
  SystemdNotifier(bool enabled, std::optional<Duration> watchdog_interval)
      : enabled_(enabled), watchdog_interval_(watchdog_interval) {}

  // Sends one NUL-terminated state string; true if sd_notify sent it.
  bool Send(const char* state) const noexcept;

  bool enabled_ = false;
  std::optional<Duration> watchdog_interval_;
};

}  // namespace rover::runtime

#endif  // ROVER_FIRMWARE_RUNTIME_HEALTH_SYSTEMD_NOTIFIER_H_
