#include "firmware/runtime/health/health_options.h"

#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

namespace rover::runtime {
namespace {

// Text that reads back as `value`, without noise digits for the usual cases
// ("60", "0.01", "90.5", "nan").
std::string Number(double value) {
  char buffer[32];
  int n = std::snprintf(buffer, sizeof(buffer), "%.15g", value);
  if (n > 0 && std::strtod(buffer, nullptr) != value && !std::isnan(value)) {
    n = std::snprintf(buffer, sizeof(buffer), "%.17g", value);
  }
  return std::string(buffer, n > 0 ? static_cast<std::size_t>(n) : 0U);
}

}  // namespace

HealthOptions HealthOptions::Load(const ConfigNode& node) {
  HealthOptions o;
  o.period_s = node.GetInRange<double>("period_s", kMinPeriodS, kMaxPeriodS, o.period_s);
  o.stale_after_s = node.Get<double>("stale_after_s", o.stale_after_s);
  o.rate_warn_fraction =
      node.GetInRange<double>("rate_warn_fraction", 0.0, 1.0, o.rate_warn_fraction);
  o.watchdog = node.Get<bool>("watchdog", o.watchdog);
  if (const auto problem = o.Problem()) node.Fail(problem->first, problem->second);
  return o;
}

std::optional<std::pair<std::string, std::string>> HealthOptions::Problem() const {
  using Result = std::pair<std::string, std::string>;
  // Negated range tests, so that NaN is rejected too.
  if (!(period_s >= kMinPeriodS && period_s <= kMaxPeriodS)) {
    return Result{"period_s", "expected a period in [" + Number(kMinPeriodS) + ", " +
                                  Number(kMaxPeriodS) + "] s, found " + Number(period_s)};
  }
  if (!(stale_after_s > 0.0 && stale_after_s <= kMaxStaleAfterS)) {
    return Result{"stale_after_s", "expected a time in (0, " + Number(kMaxStaleAfterS) +
                                       "] s, found " + Number(stale_after_s)};
  }
  if (!(rate_warn_fraction >= 0.0 && rate_warn_fraction <= 1.0)) {
    return Result{"rate_warn_fraction",
                  "expected a fraction in [0, 1], found " + Number(rate_warn_fraction)};
  }
  return std::nullopt;
}

void HealthOptions::Validate() const {
  if (const auto problem = Problem()) {
    throw std::invalid_argument("health." + problem->first + ": " + problem->second);
  }
}

SensorMonitorOptions HealthOptions::sensor_monitor_options() const {
  SensorMonitorOptions o;
  o.stale_after = Duration::FromSeconds(stale_after_s);
  o.rate_warn_fraction = rate_warn_fraction;
  return o;
}

}  // namespace rover::runtime
