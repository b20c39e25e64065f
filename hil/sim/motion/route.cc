#include "hil/sim/motion/route.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace rover::sim {
namespace {

constexpr double kMinLegLength_m = 0.01;

void CheckSpeed(double speed_m_s, const std::string& what) {
  if (!(speed_m_s >= kMinLegSpeed_m_s && speed_m_s <= kMaxLegSpeed_m_s)) {
    throw std::invalid_argument(what + ": speed " + std::to_string(speed_m_s) +
                                " m/s is outside [0.1, 0.5] m/s");
  }
}

}  // namespace

Route& Route::DriveTo(const Eigen::Vector2d& xy_m, double speed_m_s, double stop_s) {
  waypoints.push_back({xy_m, speed_m_s, stop_s});
  return *this;
}

Route& Route::Revisit(int index, double speed_m_s, double stop_s) {
  if (index < -1 || index >= static_cast<int>(waypoints.size())) {
    throw std::invalid_argument("route: revisit of waypoint " + std::to_string(index) +
                                ", which does not exist yet");
  }
  const Eigen::Vector2d xy =
      index < 0 ? start_xy_m : waypoints[static_cast<std::size_t>(index)].xy_m;
  return DriveTo(xy, speed_m_s, stop_s);
}

void Route::Validate() const {
  if (waypoints.empty()) throw std::invalid_argument("route: no waypoints");
  if (!(start_hold_s >= 0.0 && end_hold_s >= 0.0)) {
    throw std::invalid_argument("route: negative start or end hold");
  }
  Eigen::Vector2d previous = start_xy_m;
  for (std::size_t i = 0; i < waypoints.size(); ++i) {
    const Waypoint& w = waypoints[i];
    const std::string what = "route: waypoint " + std::to_string(i);
    CheckSpeed(w.speed_m_s, what);
    if (!(w.stop_s >= 0.0)) throw std::invalid_argument(what + ": negative stop_s");
    if (!((w.xy_m - previous).norm() >= kMinLegLength_m)) {
      throw std::invalid_argument(what + ": closer than 1 cm to the previous position");
    }
    previous = w.xy_m;
  }
}

Route Route::Load(const ConfigNode& node) {
  Route route;
  route.start_xy_m = node.Get<Eigen::Vector2d>("start_xy_m");
  route.start_yaw_rad = node.GetInRange<double>("start_yaw_rad", -M_PI, M_PI);
  route.start_hold_s = node.GetInRange<double>("start_hold_s", 0.0, 3600.0, route.start_hold_s);
  route.end_hold_s = node.GetInRange<double>("end_hold_s", 0.0, 3600.0, route.end_hold_s);
  const std::vector<ConfigNode> items = node.ChildList("waypoints");
  if (items.empty()) node.Fail("waypoints", "needs at least one waypoint");
  for (const ConfigNode& item : items) {
    const double speed = item.GetInRange<double>("speed_m_s", kMinLegSpeed_m_s, kMaxLegSpeed_m_s);
    const double stop = item.GetInRange<double>("stop_s", 0.0, 3600.0, 0.0);
    if (item.Has("revisit")) {
      const int index =
          item.GetInRange<int>("revisit", -1, static_cast<int>(route.waypoints.size()) - 1);
      if (item.Has("xy_m")) item.Fail("xy_m", "give either xy_m or revisit, not both");
      route.Revisit(index, speed, stop);
    } else {
      route.DriveTo(item.Get<Eigen::Vector2d>("xy_m"), speed, stop);
    }
  }
  try {
    route.Validate();
  } catch (const std::invalid_argument& e) {
    node.Fail("waypoints", e.what());
  }
  return route;
}

Route MakeSurveyLoopRoute(const Eigen::Vector2d& center_xy_m, double size_x_m, double size_y_m,
                          int laps) {
  if (laps < 1) throw std::invalid_argument("MakeSurveyLoopRoute: laps must be >= 1");
  const Eigen::Vector2d c0 = center_xy_m - 0.5 * Eigen::Vector2d(size_x_m, size_y_m);
  Route route;
  route.start_xy_m = c0;
  route.start_yaw_rad = 0.0;
  for (int lap = 0; lap < laps; ++lap) {
    // A gentle bend (about 11 degrees on a square) halfway along the first
    // side is rounded off while driving; the rectangle corners are turns on
    // the spot.
    route.DriveTo(c0 + Eigen::Vector2d(0.5 * size_x_m, -0.05 * size_y_m), 0.3)
        .DriveTo(c0 + Eigen::Vector2d(size_x_m, 0.0), 0.4)
        .DriveTo(c0 + Eigen::Vector2d(size_x_m, size_y_m), 0.2, 3.0)
        .DriveTo(c0 + Eigen::Vector2d(0.0, size_y_m), 0.5)
        .Revisit(-1, 0.3, 1.0);
  }
  return route;
}

}  // namespace rover::sim
