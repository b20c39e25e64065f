#ifndef ROVER_FIRMWARE_RUNTIME_HEALTH_HEALTH_OPTIONS_H_
#define ROVER_FIRMWARE_RUNTIME_HEALTH_HEALTH_OPTIONS_H_

// Options of the health thread (the `health` section of a board config):
//
//   health:
//     period_s: 1.0             # one snapshot, diagnostics message and status line per period
//     stale_after_s: 1.0        # a sensor silent for longer is STALE
//     rate_warn_fraction: 0.9   # WARN below this fraction of a sensor's nominal rate
//     watchdog: true            # send systemd watchdog keep-alives (if WatchdogSec= is set)
//
// Every key is optional. Unknown keys are reported by the root's
// CheckNoUnknownKeysRecursive(), as for every other section.

#include <optional>
#include <string>
#include <utility>

#include "core/config/config.h"
#include "core/time/time.h"
#include "firmware/runtime/health/sensor_monitor.h"

namespace rover::runtime {

/// How often the health thread looks and how strictly it judges.
struct HealthOptions {
  /// Longest accepted period and stale time: beyond a minute a dead sensor
  /// or a hung process would go unnoticed for too long to be of use.
  static constexpr double kMaxPeriodS = 60.0;
  static constexpr double kMaxStaleAfterS = 60.0;
  /// Shortest accepted period: the health thread is not a real-time loop.
  static constexpr double kMinPeriodS = 0.01;

  double period_s = 1.0;
  double stale_after_s = 1.0;
  double rate_warn_fraction = 0.9;
  bool watchdog = true;

  /// Reads the keys listed at the top of this file from `node` (absent keys
  /// keep their defaults). Throws ConfigError located at the offending key
  /// for a wrong type or a value Problem() rejects.
  static HealthOptions Load(const ConfigNode& node);

  /// The first invalid field as (key, "expected ..., found ...") or nullopt
  /// if valid: period_s in [0.01, 60], stale_after_s in (0, 60],
  /// rate_warn_fraction in [0, 1] (0 disables the rate check).
  std::optional<std::pair<std::string, std::string>> Problem() const;

  /// Throws std::invalid_argument "health.<key>: expected ..., found ..."
  /// if Problem() finds one.
  void Validate() const;

  /// period_s as a Duration.
  Duration period() const { return Duration::FromSeconds(period_s); }

  /// The SensorMonitor options these settings imply (stale_after,
  /// rate_warn_fraction; the rest keep SensorMonitorOptions' defaults).
  SensorMonitorOptions sensor_monitor_options() const;
};

}  // namespace rover::runtime

#endif  // ROVER_FIRMWARE_RUNTIME_HEALTH_HEALTH_OPTIONS_H_
