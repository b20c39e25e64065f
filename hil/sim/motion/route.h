#ifndef ROVER_HIL_SIM_MOTION_ROUTE_H_
#define ROVER_HIL_SIM_MOTION_ROUTE_H_

// A rover route: where to drive, how fast, where to stop. The planner
// (rover_trajectory.h) turns it into a smooth trajectory: straight legs,
// corners with a small heading change rounded off while driving, and large
// heading changes (or any change at a stop) taken as turns on the spot.
//
// Loops: a waypoint may repeat an earlier position (Revisit), which is how a
// route closes loops over places it has already seen.

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "core/config/config.h"

namespace rover::sim {

/// Speed limits of the rover on a leg.
inline constexpr double kMinLegSpeed_m_s = 0.1;
inline constexpr double kMaxLegSpeed_m_s = 0.5;

struct Waypoint {
  Eigen::Vector2d xy_m = Eigen::Vector2d::Zero();  ///< world x, y
  double speed_m_s = 0.3;  ///< cruise speed of the leg that ends here, in [0.1, 0.5]
  double stop_s = 0.0;     ///< time to stand still here on arrival (0: drive through)
};

struct Route {
  Eigen::Vector2d start_xy_m = Eigen::Vector2d::Zero();
  double start_yaw_rad = 0.0;
  double start_hold_s = 2.0;  ///< standing still before the first move (IMU initialisation)
  double end_hold_s = 2.0;    ///< standing still after the last waypoint
  std::vector<Waypoint> waypoints;

  /// Appends a waypoint; returns *this for chaining.
  Route& DriveTo(const Eigen::Vector2d& xy_m, double speed_m_s, double stop_s = 0.0);
  /// Appends a waypoint at the position of waypoint `index` (a loop closure).
  /// `index` == -1 revisits the start position.
  Route& Revisit(int index, double speed_m_s, double stop_s = 0.0);

  /// Throws std::invalid_argument unless every speed is in [0.1, 0.5] m/s,
  /// every hold is >= 0, there is at least one waypoint and no leg is shorter
  /// than 1 cm.
  void Validate() const;

  /// Loads a route from YAML:
  ///   start_xy_m: [x, y]
  ///   start_yaw_rad: 0.0
  ///   start_hold_s: 2.0            # optional
  ///   end_hold_s: 2.0              # optional
  ///   waypoints:
  ///     - {xy_m: [5, 0], speed_m_s: 0.3, stop_s: 0}   # stop_s optional
  ///     - {revisit: 0, speed_m_s: 0.2}                  # loop closure to waypoint 0
  /// Ranges are checked; the result is validated.
  static Route Load(const ConfigNode& node);
};

/// A closed survey route around a rectangle centred on `center_xy_m` with
/// sides size_x_m x size_y_m: corners taken as turns on the spot, a slightly
/// bent middle leg (a corner rounded off while driving), a stop, speeds
/// varying per leg, and every lap ending back at the start pose (loop
/// closure). `laps` >= 1.
Route MakeSurveyLoopRoute(const Eigen::Vector2d& center_xy_m, double size_x_m, double size_y_m,
                          int laps);

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_MOTION_ROUTE_H_
