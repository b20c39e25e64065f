#ifndef ROVER_ESTIMATOR_EVAL_EVAL_ERROR_H_
#define ROVER_ESTIMATOR_EVAL_EVAL_ERROR_H_

// The one exception type of the trajectory-evaluation library.

#include <stdexcept>

namespace rover::eval {

/// Thrown for input the evaluation cannot use: unreadable or malformed files
/// (the message starts with "FILE:LINE: expected ..., found ..."), invalid
/// trajectories, too few poses for an alignment, empty overlap between an
/// estimate and its ground truth.
class EvalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace rover::eval

#endif  // ROVER_ESTIMATOR_EVAL_EVAL_ERROR_H_
