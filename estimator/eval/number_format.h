#ifndef ROVER_ESTIMATOR_EVAL_NUMBER_FORMAT_H_
#define ROVER_ESTIMATOR_EVAL_NUMBER_FORMAT_H_

// Lossless number formatting for the trajectory writers and error messages.

#include <string>

#include "core/time/time.h"

namespace rover::eval {

/// The shortest decimal text that reads back as exactly `value`
/// (std::to_chars round-trip form), e.g. "0.1", "1e-300", "nan", "inf".
std::string FormatDouble(double value);

/// `time` as decimal seconds with all nine nanosecond digits, exact:
/// 1403715273262142976 ns -> "1403715273.262142976", -1 ns -> "-0.000000001".
std::string FormatSeconds(Time time);

}  // namespace rover::eval

#endif  // ROVER_ESTIMATOR_EVAL_NUMBER_FORMAT_H_
