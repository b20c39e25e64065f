#ifndef ROVER_ESTIMATOR_EVAL_CSV_TRAJECTORY_H_
#define ROVER_ESTIMATOR_EVAL_CSV_TRAJECTORY_H_

// Comma-separated trajectory files:
//
//  * EuRoC ground truth (mav0/state_groundtruth_estimate0/data.csv) and
//    EuRoC-style estimates: fixed columns
//      #timestamp [ns], p_RS_R_x [m], p_RS_R_y, p_RS_R_z, q_RS_w [], q_RS_x, q_RS_y, q_RS_z
//    optionally followed by v_RS_R_x [m s^-1], v_RS_R_y, v_RS_R_z and more
//    columns (biases), which are ignored. Note the quaternion is w first.
//  * OpenVINS-style CSVs, whose header names the columns, e.g.
//      #time(ns),px,py,pz,qw,qx,qy,qz,vx,vy,vz,...
//    The layout (time column and unit, position, quaternion order, optional
//    velocity) is taken from the header; see CsvLayoutFromHeader().
//
// Stamps must increase strictly; quaternions must have unit norm to 1e-3 and
// are normalized. Every problem is an EvalError "FILE:LINE: expected ..., found ...".

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "estimator/eval/trajectory.h"

namespace rover::eval {

/// Which column holds what (0-based), and the unit of the time column.
struct CsvLayout {
  enum class TimeUnit {
    kNanoseconds,
    kSeconds,
    kUnknown,  ///< Decided per cell: a '.' or exponent means seconds, an integer nanoseconds.
  };
  std::size_t time = 0;
  TimeUnit time_unit = TimeUnit::kNanoseconds;
  std::array<std::size_t, 3> position{1, 2, 3};
  std::array<std::size_t, 4> quaternion_wxyz{4, 5, 6, 7};  ///< Columns of w, x, y, z.
  std::optional<std::array<std::size_t, 3>> velocity;

  /// Number of columns a data row needs.
  std::size_t MinColumns() const;
  friend bool operator==(const CsvLayout&, const CsvLayout&) = default;
};

/// The fixed EuRoC layout: t [ns], p xyz, q wxyz (no velocity).
CsvLayout EurocCsvLayout();

/// Derives a layout from the header cells (without the leading '#'). Column
/// names are compared case-insensitively with units in [] or () and the
/// characters ' ', '_' and '-' removed; recognised names include
///   time:       timestamp, time, t, stamp (unit from "[ns]", "(s)", "_ns", ...)
///   position:   px/tx/x/pos_x/position_x/p_RS_R_x (and y, z)
///   quaternion: qw/q_w/q_RS_w/quat_w/orientation_w (and x, y, z, in any order)
///   velocity:   vx/v_x/vel_x/v_RS_R_x (optional)
/// Returns nullopt (and a reason in *problem, if given) when the time,
/// position or quaternion columns are not all found.
std::optional<CsvLayout> CsvLayoutFromHeader(const std::vector<std::string_view>& cells,
                                             std::string* problem = nullptr);

/// True if the header cells are EuRoC's own names (p_RS_R_x, q_RS_w, ...).
bool IsEurocHeader(const std::vector<std::string_view>& cells);

/// Reads a CSV with the fixed EuRoC layout (EurocCsvLayout(); velocity is
/// read when the header names it in columns 8-10 or, without a header, when
/// rows have at least 11 columns). A header that names a different layout is
/// an error suggesting the "openvins" format. Throws EvalError.
Trajectory ReadEurocCsvTrajectory(const std::string& path);

/// Reads a CSV whose header names its columns (CsvLayoutFromHeader()); a file
/// without such a header is an error. Throws EvalError.
Trajectory ReadOpenVinsCsvTrajectory(const std::string& path);

/// Writes `trajectory` in the EuRoC layout with EuRoC's header, full double
/// precision (shortest round-trip form) and integer nanosecond stamps; adds
/// velocity columns when every sample has a velocity. Throws EvalError if the
/// file cannot be written.
void WriteEurocCsvTrajectory(const Trajectory& trajectory, const std::string& path);

}  // namespace rover::eval

#endif  // ROVER_ESTIMATOR_EVAL_CSV_TRAJECTORY_H_
