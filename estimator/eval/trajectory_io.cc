#include "estimator/eval/trajectory_io.h"

#include "estimator/eval/csv_trajectory.h"
#include "estimator/eval/eval_error.h"
#include "estimator/eval/tum_trajectory.h"

namespace rover::eval {

Trajectory ReadTrajectory(const std::string& path, const TrajectoryReadOptions& options,
                          TrajectoryFormat* detected) {
  const TrajectoryFormat format =
      options.format == TrajectoryFormat::kAuto ? DetectTrajectoryFormat(path) : options.format;
  if (detected != nullptr) *detected = format;
  Trajectory trajectory;
  switch (format) {
    case TrajectoryFormat::kTum:
      trajectory = ReadTumTrajectory(path);
      break;
    case TrajectoryFormat::kEuroc:
      trajectory = ReadEurocCsvTrajectory(path);
      break;
    case TrajectoryFormat::kOpenVins:
      trajectory = ReadOpenVinsCsvTrajectory(path);
      break;
    case TrajectoryFormat::kMcap:
      trajectory = ReadMcapTrajectory(path, options.mcap).trajectory;
      break;
    case TrajectoryFormat::kAuto:
      throw EvalError(path + ": internal error: format not detected");
  }
  trajectory.set_source(path);
  trajectory.Validate();
  return trajectory;
}

void WriteTrajectory(const Trajectory& trajectory, const std::string& path,
                     TrajectoryFormat format) {
  switch (format) {
    case TrajectoryFormat::kTum:
      WriteTumTrajectory(trajectory, path);
      return;
    case TrajectoryFormat::kEuroc:
      WriteEurocCsvTrajectory(trajectory, path);
      return;
    default:
      throw EvalError(path + ": expected an output format of tum or euroc, found " +
                      std::string(ToString(format)));
  }
}

}  // namespace rover::eval
