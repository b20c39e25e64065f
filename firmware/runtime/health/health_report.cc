#include "firmware/runtime/health/health_report.h"

#include <algorithm>
#include <cstdio>

#include "core/log/msgs/builtin_interfaces.h"

namespace rover::runtime {
namespace {

using log::diagnostic_msgs::DiagnosticStatus;
using log::diagnostic_msgs::KeyValue;

// HealthLevel is converted to the message's byte with a cast; these keep the
// two definitions from drifting apart.
static_assert(static_cast<uint8_t>(HealthLevel::kOk) == DiagnosticStatus::kOk);
static_assert(static_cast<uint8_t>(HealthLevel::kWarn) == DiagnosticStatus::kWarn);
static_assert(static_cast<uint8_t>(HealthLevel::kError) == DiagnosticStatus::kError);
static_assert(static_cast<uint8_t>(HealthLevel::kStale) == DiagnosticStatus::kStale);

// Fixed-point text with `decimals` decimals; "inf" / "nan" as printf spells them.
std::string Fixed(double value, int decimals) {
  char buffer[64];
  const int n = std::snprintf(buffer, sizeof(buffer), "%.*f", decimals, value);
  return n < 0 ? std::string()
               : std::string(buffer, std::min(sizeof(buffer) - 1, static_cast<std::size_t>(n)));
}

std::string Microseconds(int64_t ns) { return Fixed(static_cast<double>(ns) * 1e-3, 1); }

std::string Bool(bool value) { return value ? "true" : "false"; }

// "1 new drop", "3 new drops".
std::string Counted(uint64_t n, const char* what) {
  return std::to_string(n) + " new " + what + (n == 1 ? "" : "s");
}

// Why a sensor is not ok, one phrase per problem, worst first.
std::vector<std::string> Problems(const SensorHealth& s, bool with_stale_and_rate) {
  std::vector<std::string> problems;
  if (with_stale_and_rate && s.level == HealthLevel::kStale) {
    problems.push_back(s.has_sample ? "no sample for " + Fixed(s.since_last_sample_s, 1) + " s"
                                    : "no sample yet");
  }
  if (s.new_errors > 0) problems.push_back(Counted(s.new_errors, "error"));
  if (s.new_drops > 0) problems.push_back(Counted(s.new_drops, "drop"));
  if (s.new_gaps > 0) problems.push_back(Counted(s.new_gaps, "gap"));
  if (with_stale_and_rate && s.rate_low) {
    problems.push_back("rate " + Fixed(s.rate_hz, 1) + " Hz, nominal " +
                       Fixed(s.nominal_rate_hz, 1) + " Hz");
  }
  return problems;
}

std::string Join(const std::vector<std::string>& parts, const char* separator) {
  std::string out;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (i > 0) out += separator;
    out += parts[i];
  }
  return out;
}

}  // namespace

void HealthReport::AddSensor(const SensorHealth& s) {
  Entry entry;
  DiagnosticStatus& status = entry.status;
  status.level = static_cast<uint8_t>(s.level);
  status.name = s.name;
  const std::vector<std::string> problems = Problems(s, /*with_stale_and_rate=*/true);
  status.message = problems.empty() ? "ok" : Join(problems, "; ");

  std::vector<KeyValue>& v = status.values;
  v.push_back({"rate_hz", Fixed(s.rate_hz, 2)});
  v.push_back({"nominal_rate_hz", Fixed(s.nominal_rate_hz, 2)});
  v.push_back({"rate_window_s", Fixed(s.rate_window_s, 3)});
  v.push_back({"rate_judged", Bool(s.rate_judged)});
  v.push_back({"since_last_s", s.has_sample ? Fixed(s.since_last_sample_s, 3) : "inf"});
  v.push_back({"interval_s", Fixed(s.interval_s, 3)});
  v.push_back({"samples", std::to_string(s.samples)});
  v.push_back({"drops", std::to_string(s.drops)});
  v.push_back({"errors", std::to_string(s.errors)});
  v.push_back({"gaps", std::to_string(s.gaps)});
  v.push_back({"new_drops", std::to_string(s.new_drops)});
  v.push_back({"new_errors", std::to_string(s.new_errors)});
  v.push_back({"new_gaps", std::to_string(s.new_gaps)});
  v.push_back({"longest_gap_s", Fixed(s.longest_gap_s, 3)});
  if (s.latency_measured) {
    v.push_back({"latency_count", std::to_string(s.latency.count)});
    v.push_back({"latency_p50_us", Microseconds(s.latency.p50_ns)});
    v.push_back({"latency_p99_us", Microseconds(s.latency.p99_ns)});
    v.push_back({"latency_max_us", Microseconds(s.latency.max_ns)});
  }

  // Status line: the age for a stale sensor, else the rate (against the
  // nominal rate when too low), then the remaining problems.
  std::string& line = entry.summary;
  line = s.name + " " + std::string(HealthLevelName(s.level)) + " ";
  if (s.level == HealthLevel::kStale) {
    line += s.has_sample ? Fixed(s.since_last_sample_s, 1) + " s" : "no data";
  } else if (s.rate_low) {
    line += Fixed(s.rate_hz, 1) + "/" + Fixed(s.nominal_rate_hz, 1) + " Hz";
  } else {
    line += Fixed(s.rate_hz, 1) + " Hz";
  }
  const std::vector<std::string> others = Problems(s, /*with_stale_and_rate=*/false);
  if (!others.empty()) line += " (" + Join(others, ", ") + ")";
  entries_.push_back(std::move(entry));
}

void HealthReport::AddSensors(std::span<const SensorHealth> sensors) {
  for (const SensorHealth& s : sensors) AddSensor(s);
}

void HealthReport::AddStatus(std::string name, HealthLevel level, std::string message,
                             Values values) {
  Entry entry;
  entry.summary = name + " " + std::string(HealthLevelName(level));
  if (!message.empty() && message != HealthLevelName(level)) entry.summary += " " + message;
  DiagnosticStatus& status = entry.status;
  status.level = static_cast<uint8_t>(level);
  status.name = std::move(name);
  status.message = std::move(message);
  status.values.reserve(values.size());
  for (auto& [key, value] : values) status.values.push_back({std::move(key), std::move(value)});
  entries_.push_back(std::move(entry));
}

log::diagnostic_msgs::DiagnosticArray HealthReport::ToDiagnosticArray(Time stamp) const {
  log::diagnostic_msgs::DiagnosticArray array;
  array.header.stamp = log::ToRosTime(stamp);
  array.status.reserve(entries_.size());
  for (const Entry& entry : entries_) array.status.push_back(entry.status);
  return array;
}

std::string HealthReport::OneLine() const {
  std::string line;
  for (const Entry& entry : entries_) {
    if (!line.empty()) line += ", ";
    line += entry.summary;
  }
  return line;
}

uint8_t HealthReport::WorstLevel() const {
  uint8_t worst = DiagnosticStatus::kOk;
  for (const Entry& entry : entries_) worst = std::max(worst, entry.status.level);
  return worst;
}

}  // namespace rover::runtime
