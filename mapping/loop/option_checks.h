#ifndef ROVER_MAPPING_LOOP_OPTION_CHECKS_H_
#define ROVER_MAPPING_LOOP_OPTION_CHECKS_H_

// Validate() helpers of the loop-closure options: one error format,
// "<Component>.<key>: expected <range>, got <value>".

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace rover::mapping::loop_internal {

[[noreturn]] inline void FailOption(const char* component, const char* key, const char* expected,
                                    double got) {
  std::ostringstream s;
  s << component << "." << key << ": expected " << expected << ", got " << got;
  throw std::invalid_argument(s.str());
}

/// Finite and lo <= value <= hi.
inline void CheckRange(const char* component, const char* key, double value, double lo, double hi) {
  if (!(std::isfinite(value) && value >= lo && value <= hi)) {
    std::ostringstream expected;
    expected << "a finite value in [" << lo << ", " << hi << "]";
    FailOption(component, key, expected.str().c_str(), value);
  }
}

/// Finite and > 0.
inline void CheckPositive(const char* component, const char* key, double value) {
  if (!(std::isfinite(value) && value > 0.0)) FailOption(component, key, "finite and > 0", value);
}

}  // namespace rover::mapping::loop_internal

#endif  // ROVER_MAPPING_LOOP_OPTION_CHECKS_H_
