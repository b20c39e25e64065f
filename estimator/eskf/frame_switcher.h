#ifndef ROVER_ESTIMATOR_ESKF_FRAME_SWITCHER_H_
#define ROVER_ESTIMATOR_ESKF_FRAME_SWITCHER_H_

// Frame-of-reference switch: moves the local frame into the unobservable part
// (x, y, z, yaw) of the current body pose and transforms the nominal state,
// every clone and the joint covariance with the exact Jacobian. Derivation in
// README.md ("Frame switch").

#include "estimator/eskf/eskf_output.h"
#include "estimator/eskf/state/filter_state.h"

namespace rover::estimator {

class FrameSwitcher {
 public:
  /// Switches `state` into the frame N with T_old_N = (p, Rz(yaw)) of the
  /// current pose, increments state.frame_id and returns the switch record
  /// (T_old_new with the 4x4 covariance of [p; yaw] before the switch).
  /// Afterwards p = 0 and yaw = 0 exactly, the position rows/columns of the
  /// covariance are zero and the yaw direction J_yaw dtheta has zero variance;
  /// roll, pitch, velocity, biases and clones keep their (transformed)
  /// uncertainty and correlations.
  static FrameSwitchRecord Switch(FilterState& state);

  /// The same transformation without changing frame_id or producing a
  /// record; used once at initialisation to make the initial position and
  /// yaw uncertainty exactly zero.
  static void ResetPositionAndYaw(FilterState& state);
};

}  // namespace rover::estimator

#endif  // ROVER_ESTIMATOR_ESKF_FRAME_SWITCHER_H_
