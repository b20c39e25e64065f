#ifndef ROVER_FIRMWARE_RUNTIME_HEALTH_HEALTH_REPORT_H_
#define ROVER_FIRMWARE_RUNTIME_HEALTH_HEALTH_REPORT_H_

// One health cycle's findings, in the two forms the firmware publishes them:
//   - a diagnostic_msgs/DiagnosticArray for the flight log (one
//     DiagnosticStatus per sensor or component, with its numbers as
//     key/value pairs whose keys carry their unit: "rate_hz",
//     "latency_p99_us", "since_last_s");
//   - one line for systemd's STATUS= (SystemdNotifier::Status), e.g.
//     "imu ok 400.0 Hz, camera ok 10.0 Hz, can STALE 1.2 s".
//
// Built on the health thread, which is not real-time: it allocates freely.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/log/msgs/diagnostic_msgs.h"
#include "core/time/time.h"
#include "firmware/runtime/health/sensor_monitor.h"

namespace rover::runtime {

/// Collects sensor and component statuses of one health cycle. Create one
/// per cycle (or Clear() it).
class HealthReport {
 public:
  /// Key/value pairs of a free-form component; keys should carry units.
  using Values = std::vector<std::pair<std::string, std::string>>;

  /// Adds one sensor's status: its level, a message saying why it is not
  /// ok (or "ok"), and its numbers (rates, totals, interval counts, gap,
  /// age of the last sample, latency percentiles if measured).
  void AddSensor(const SensorHealth& sensor);

  /// AddSensor() for each element, in order.
  void AddSensors(std::span<const SensorHealth> sensors);

  /// Adds a free-form component (estimator, logger, disk, ...) with its
  /// level, a human-readable message and key/value pairs, kept in order.
  void AddStatus(std::string name, HealthLevel level, std::string message, Values values = {});

  /// The statuses added so far, in order, with header.stamp = `stamp`
  /// (CLOCK_MONOTONIC, as every stamp of the flight log).
  log::diagnostic_msgs::DiagnosticArray ToDiagnosticArray(Time stamp) const;

  /// One line summarising every status, comma-separated in order: a sensor
  /// as "<name> <level> <rate> Hz" (with "/<nominal>" when the rate is too
  /// low, and its other problems in parentheses), a stale one as
  /// "<name> STALE <age> s" or "<name> STALE no data", a component as
  /// "<name> <level> <message>". Levels are "ok", "WARN", "ERROR", "STALE".
  /// Empty if nothing was added. Contains no line break if no name or
  /// message does (SystemdNotifier::Status() replaces any anyway).
  std::string OneLine() const;

  /// The worst (numerically highest) level added, as the DiagnosticStatus
  /// byte: kOk (0) .. kStale (3); kOk if nothing was added.
  uint8_t WorstLevel() const;

  /// Number of statuses added.
  std::size_t size() const { return entries_.size(); }

  /// Forgets every status (keeps the capacity, for the next cycle).
  void Clear() { entries_.clear(); }

 private:
  struct Entry {
    log::diagnostic_msgs::DiagnosticStatus status;
    std::string summary;  // This entry's part of OneLine().
  };

  std::vector<Entry> entries_;
};

}  // namespace rover::runtime

#endif  // ROVER_FIRMWARE_RUNTIME_HEALTH_HEALTH_REPORT_H_
