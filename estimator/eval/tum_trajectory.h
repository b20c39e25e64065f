#ifndef ROVER_ESTIMATOR_EVAL_TUM_TRAJECTORY_H_
#define ROVER_ESTIMATOR_EVAL_TUM_TRAJECTORY_H_

// TUM RGB-D trajectory files: one pose per line,
//   timestamp tx ty tz qx qy qz qw
// separated by spaces or tabs, timestamp in seconds, quaternion x y z w
// (scalar last), '#' comment lines. Columns after the eighth are ignored
// (OpenVINS appends covariance entries there).

#include <string>

#include "estimator/eval/trajectory.h"

namespace rover::eval {

/// Reads a TUM file. Stamps are parsed exactly to the nanosecond, must
/// increase strictly; quaternions must have unit norm to 1e-3 and are
/// normalized. Throws EvalError "FILE:LINE: expected ..., found ...".
Trajectory ReadTumTrajectory(const std::string& path);

/// Writes `trajectory` as TUM with a '#' header line, stamps as exact decimal
/// seconds (9 decimals) and full double precision for the values.
/// Covariances and velocities are not written. Throws EvalError on I/O failure.
void WriteTumTrajectory(const Trajectory& trajectory, const std::string& path);

}  // namespace rover::eval

#endif  // ROVER_ESTIMATOR_EVAL_TUM_TRAJECTORY_H_
