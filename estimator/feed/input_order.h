#ifndef ROVER_ESTIMATOR_FEED_INPUT_ORDER_H_
#define ROVER_ESTIMATOR_FEED_INPUT_ORDER_H_

// The one order in which the local reference filter takes its inputs. The
// filter is a pure function of its ordered inputs, so every producer of that
// order (roverd's IMU thread, the simulator's feed, `rover-eval vio`) must
// agree on it to the last tie; they all use this comparator.
//
// Order: by time stamp; at equal stamps by kind:
//   IMU sample, wheel speeds, clone trigger, relative pose, frame-switch
//   request, pose-report request;
// inputs of one kind and one stamp keep their arrival order (stable).
//
// Why the IMU sample first: the sample at t carries the state to t, so a
// measurement stamped t is applied to the state at t (a wheel speed is not
// applied to the state one IMU period old, and a clone trigger at t clones
// the propagated state without interpolation). Triggers come before relative
// poses because a relative pose refers to the clones the triggers make.

#include <vector>

#include "estimator/eskf/eskf_input.h"

namespace rover::estimator {

/// The tie-break rank of an input's kind at equal stamps (lower first).
int InputRank(const EskfInput& input);

/// True when `a` goes to the filter strictly before `b`: earlier stamp, or
/// equal stamps and a lower InputRank().
bool InputBefore(const EskfInput& a, const EskfInput& b);

/// Sorts `inputs` into the filter's order (stable: equal keys keep their
/// order). For offline producers that hold the whole sequence.
void SortInputs(std::vector<EskfInput>* inputs);

}  // namespace rover::estimator

#endif  // ROVER_ESTIMATOR_FEED_INPUT_ORDER_H_
