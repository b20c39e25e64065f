#ifndef ROVER_ESTIMATOR_ESKF_UPDATE_RELATIVE_POSE_UPDATER_H_
#define ROVER_ESTIMATOR_ESKF_UPDATE_RELATIVE_POSE_UPDATER_H_

// The delayed relative-pose (keyframe VO) measurement between two clones a
// (keyframe) and b (current frame):
//   h(x) = T_a^-1 T_b:  p_ab = R_a^T (p_b - p_a),  R_ab = R_a^T R_b.
// Residual r = [p_meas - p_ab; Log(R_ab^T R_meas)]. With body-side clone
// errors, linearised about the estimate (r0 = rotation residual):
//   d p_ab = R_a^T (dp_b - dp_a) + [p_ab]x dtheta_a
//   r_rot ~ r0 - Jl^-1(r0) (dtheta_b - R_ab^T dtheta_a)
// and the stated rotation noise n enters as Jr^-1(r0) n. Because the clones
// are correlated with the current state, the update also corrects the
// current pose: that is the delay compensation.

#include "estimator/eskf/eskf_input.h"
#include "estimator/eskf/eskf_options.h"
#include "estimator/eskf/state/filter_state.h"
#include "estimator/eskf/update/kalman_update.h"

namespace rover::estimator {

class RelativePoseUpdater {
 public:
  explicit RelativePoseUpdater(const RelativePoseOptions& options);

  /// The linearised measurement between clones ia and ib of `state`.
  LinearisedMeasurement<6, 4> Linearise(const FilterState& state, const RelativePoseMeasurement& z,
                                        int ia, int ib) const;

  /// Gates and applies the measurement (Joseph form).
  UpdateOutcome Update(FilterState& state, const RelativePoseMeasurement& z, int ia, int ib) const;

  double gate() const { return gate_; }

 private:
  RelativePoseOptions options_;
  double gate_;  ///< chi-square threshold, 6 dof
};

}  // namespace rover::estimator

#endif  // ROVER_ESTIMATOR_ESKF_UPDATE_RELATIVE_POSE_UPDATER_H_
