#ifndef ROVER_ESTIMATOR_EVAL_TRAJECTORY_FORMAT_H_
#define ROVER_ESTIMATOR_EVAL_TRAJECTORY_FORMAT_H_

// The trajectory file formats the evaluation tools read and write, and their
// detection from a file's extension and content.

#include <optional>
#include <string>
#include <string_view>

namespace rover::eval {

enum class TrajectoryFormat {
  kAuto,      ///< Detect with DetectTrajectoryFormat().
  kTum,       ///< "timestamp_s tx ty tz qx qy qz qw", whitespace separated, '#' comments.
  kEuroc,     ///< CSV "t_ns, px, py, pz, qw, qx, qy, qz[, vx, vy, vz, ...]" (fixed columns).
  kOpenVins,  ///< CSV whose header line names the columns (time unit, quaternion order).
  kMcap,      ///< Rover flight log: nav_msgs/Odometry (+ frame switches), see mcap_trajectory.h.
};

/// "auto", "tum", "euroc", "openvins", "mcap".
std::string_view ToString(TrajectoryFormat format);

/// Inverse of ToString(); nullopt for an unknown name.
std::optional<TrajectoryFormat> ParseTrajectoryFormat(std::string_view name);

/// Detects the format of the file at `path`:
///   * MCAP: the file starts with the MCAP magic (or is named *.mcap);
///   * kTum if the first data line has no commas;
///   * otherwise a CSV: kOpenVins if the header line (the first '#' or
///     non-numeric line) names time, position and quaternion columns other
///     than EuRoC's own names, else kEuroc (fixed columns).
/// Throws EvalError if the file cannot be opened or has no data.
TrajectoryFormat DetectTrajectoryFormat(const std::string& path);

}  // namespace rover::eval

#endif  // ROVER_ESTIMATOR_EVAL_TRAJECTORY_FORMAT_H_
