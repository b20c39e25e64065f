#ifndef ROVER_ESTIMATOR_EVAL_TRAJECTORY_IO_H_
#define ROVER_ESTIMATOR_EVAL_TRAJECTORY_IO_H_

// One entry point to read or write a trajectory in any supported format
// (trajectory_format.h); the format-specific functions live in
// tum_trajectory.h, csv_trajectory.h and mcap_trajectory.h.

#include <string>

#include "estimator/eval/mcap_trajectory.h"
#include "estimator/eval/trajectory.h"
#include "estimator/eval/trajectory_format.h"

namespace rover::eval {

struct TrajectoryReadOptions {
  /// kAuto detects the format with DetectTrajectoryFormat().
  TrajectoryFormat format = TrajectoryFormat::kAuto;
  /// Topics used when the file is an MCAP flight log.
  McapTrajectoryOptions mcap;
};

/// Reads the trajectory at `path`, validates it (Trajectory::Validate()) and
/// returns it with source() == path. *detected, if given, receives the format
/// actually read. Throws EvalError with "FILE:LINE: expected ..., found ..."
/// (or the MCAP equivalent) for anything it cannot use.
Trajectory ReadTrajectory(const std::string& path, const TrajectoryReadOptions& options = {},
                          TrajectoryFormat* detected = nullptr);

/// Writes `trajectory` to `path` as kTum or kEuroc (full precision). Throws
/// EvalError for other formats or on I/O failure.
void WriteTrajectory(const Trajectory& trajectory, const std::string& path,
                     TrajectoryFormat format);

}  // namespace rover::eval

#endif  // ROVER_ESTIMATOR_EVAL_TRAJECTORY_IO_H_
