#include "hil/sim/scenario/scenario.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <stdexcept>

namespace rover::sim {
namespace {

namespace fs = std::filesystem;

WorldOptions LoadWorldOptions(const ConfigNode& node) {
  WorldOptions o;
  o.size_m = node.GetInRange<double>("size_m", 20.0, 400.0, o.size_m);
  o.resolution_m = node.GetInRange<double>("resolution_m", 0.01, 0.05, o.resolution_m);
  o.albedo_resolution_m =
      node.GetInRange<double>("albedo_resolution_m", 0.005, 0.1, o.albedo_resolution_m);
  o.max_slope_deg = node.GetInRange<double>("max_slope_deg", 0.0, 30.0, o.max_slope_deg);
  o.rock_count = node.GetInRange<int>("rock_count", 0, 100000, o.rock_count);
  o.crater_count = node.GetInRange<int>("crater_count", 0, 50, o.crater_count);
  o.landmark_post_count =
      node.GetInRange<int>("landmark_post_count", 0, 100, o.landmark_post_count);
  o.other_rover_count = node.GetInRange<int>("other_rover_count", 0, 10, o.other_rover_count);
  o.tag_size_m = node.GetInRange<double>("tag_size_m", 0.02, 1.0, o.tag_size_m);
  o.clear_radius_m = node.GetInRange<double>("clear_radius_m", 0.0, 50.0, o.clear_radius_m);
  if (node.Has("crater_centers_xy_m")) {  // flat list: [x0, y0, x1, y1, ...]
    const auto xy = node.Get<std::vector<double>>("crater_centers_xy_m");
    if (xy.size() % 2 != 0) node.Fail("crater_centers_xy_m", "expected x, y pairs");
    for (std::size_t i = 0; i + 1 < xy.size(); i += 2) {
      o.crater_centers_xy_m.emplace_back(xy[i], xy[i + 1]);
    }
  }
  if (node.Has("landmark_posts_xy_m")) {  // flat list: [x0, y0, x1, y1, ...]
    const auto xy = node.Get<std::vector<double>>("landmark_posts_xy_m");
    if (xy.size() % 2 != 0) node.Fail("landmark_posts_xy_m", "expected x, y pairs");
    for (std::size_t i = 0; i + 1 < xy.size(); i += 2) {
      o.landmark_posts_xy_m.emplace_back(xy[i], xy[i + 1]);
    }
    if (static_cast<int>(o.landmark_posts_xy_m.size()) > o.landmark_post_count) {
      node.Fail("landmark_posts_xy_m", "more posts placed than landmark_post_count (" +
                                           std::to_string(o.landmark_post_count) + ")");
    }
  }
  return o;
}

// How far inside the world's edge every route point and placed post must
// stay [m]: the rover stands on the heightfield with ground around it.
constexpr double kRouteMarginM = 5.0;

std::string EnvOr(const char* name, const std::string& fallback) {
  const char* value = std::getenv(name);
  return value != nullptr && *value != '\0' ? value : fallback;
}

}  // namespace

Scenario LoadScenario(const std::string& path, const std::string& config_dir) {
  const ConfigNode root = ConfigNode::LoadFile(path);
  Scenario s;
  s.source_path = path;
  s.name = root.Get<std::string>("name");
  s.description = root.Get<std::string>("description");
  if (root.Has("world")) s.world = LoadWorldOptions(root.Child("world"));
  s.route = Route::Load(root.Child("route"));
  if (root.Has("other_rovers")) {
    for (const ConfigNode& other : root.ChildList("other_rovers")) {
      s.other_rover_routes.push_back(Route::Load(other.Child("route")));
      other.CheckNoUnknownKeys();
    }
  }
  // Rovers never drive over rocks: keep every route's corridor clear.
  const auto keep_clear = [&s](const Route& route) {
    std::vector<Eigen::Vector2d> corridor{route.start_xy_m};
    for (const Waypoint& w : route.waypoints) corridor.push_back(w.xy_m);
    s.world.clear_paths_xy_m.push_back(std::move(corridor));
  };
  keep_clear(s.route);
  for (const Route& other : s.other_rover_routes) keep_clear(other);
  // A route that leaves the world drives off the heightfield: the cameras
  // see nothing there and the filter's VO fails, silently.
  const double half_m = 0.5 * s.world.size_m - kRouteMarginM;
  const auto check_inside = [&](const std::string& key, const std::string& what,
                                const Eigen::Vector2d& xy) {
    if (std::abs(xy.x()) > half_m || std::abs(xy.y()) > half_m) {
      std::ostringstream why;
      why << what << " at (" << xy.x() << ", " << xy.y() << ") m is outside the " << s.world.size_m
          << " m world (expected |x| and |y| <= " << half_m << " m, " << kRouteMarginM
          << " m inside its edge; make world.size_m larger)";
      root.Fail(key, why.str());
    }
  };
  const auto check_route = [&](const Route& route, const std::string& key) {
    check_inside(key, "the start", route.start_xy_m);
    for (std::size_t k = 0; k < route.waypoints.size(); ++k) {
      check_inside(key, "waypoint " + std::to_string(k), route.waypoints[k].xy_m);
    }
  };
  check_route(s.route, "route");
  for (const Route& other : s.other_rover_routes) check_route(other, "other_rovers");
  for (std::size_t k = 0; k < s.world.landmark_posts_xy_m.size(); ++k) {
    check_inside("world", "landmark post " + std::to_string(k), s.world.landmark_posts_xy_m[k]);
  }
  // With other rovers around, every rover carries tags: sightings are mutual.
  s.world.recording_rover_carries_tags = !s.other_rover_routes.empty();
  if (static_cast<int>(s.other_rover_routes.size()) != s.world.other_rover_count) {
    root.Fail("other_rovers", "has " + std::to_string(s.other_rover_routes.size()) +
                                  " routes but world.other_rover_count is " +
                                  std::to_string(s.world.other_rover_count));
  }
  const ConfigNode sensors = root.Child("sensors");
  s.imu = ImuModelOptions::LoadFile(
      (fs::path(config_dir) / sensors.Get<std::string>("imu_config")).string());
  if (sensors.Has("camera")) s.camera = StereoCameraOptions::Load(sensors.Child("camera"));
  s.ground_truth_rate_hz =
      sensors.GetInRange<double>("ground_truth_rate_hz", 10.0, 1000.0, s.ground_truth_rate_hz);
  if (sensors.Has("wheels_config")) {
    s.wheels_config = (fs::path(config_dir) / sensors.Get<std::string>("wheels_config")).string();
  }
  if (sensors.Has("gpio_config")) {
    s.gpio = GpioEdgeOptions::LoadFile(
        (fs::path(config_dir) / sensors.Get<std::string>("gpio_config")).string());
  }
  s.gpio.camera_rate_hz = s.camera.rate_hz;
  root.CheckNoUnknownKeysRecursive();
  return s;
}

std::string DefaultScenarioDir() {
  return EnvOr("ROVER_SCENARIO_DIR", std::string(ROVER_SOURCE_DIR) + "/hil/scenarios");
}

std::string DefaultSimConfigDir() {
  return EnvOr("ROVER_SIM_CONFIG_DIR", std::string(ROVER_SOURCE_DIR) + "/hil/config");
}

std::vector<std::string> ListScenarioFiles(const std::string& dir) {
  std::vector<std::string> files;
  if (!fs::is_directory(dir)) return files;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().extension() == ".yaml") files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::string FindScenario(const std::string& dir, const std::string& name) {
  const fs::path path = fs::path(dir) / (name + ".yaml");
  if (fs::exists(path)) return path.string();
  std::string known;
  for (const std::string& f : ListScenarioFiles(dir)) {
    known += (known.empty() ? "" : ", ") + fs::path(f).stem().string();
  }
  throw std::invalid_argument("unknown scenario '" + name + "' (known: " + known + "; in " + dir +
                              ")");
}

}  // namespace rover::sim
