#ifndef ROVER_HIL_SIM_SCENARIO_SCENARIO_H_
#define ROVER_HIL_SIM_SCENARIO_SCENARIO_H_

// A scenario is one YAML file in hil/scenarios/: the world to generate, the
// route the rover drives (and the routes of other tag-carrying rovers), and
// the sensor configuration. `rover-sim list` shows them; `rover-sim generate`
// turns one into a dataset.

#include <string>
#include <vector>

#include "hil/sim/motion/route.h"
#include "hil/sim/render/stereo_camera.h"
#include "hil/sim/sensors/gpio_edge_model.h"
#include "hil/sim/sensors/imu_model.h"
#include "hil/sim/world/world.h"

namespace rover::sim {

struct Scenario {
  std::string name;
  std::string description;
  std::string source_path;
  WorldOptions world;
  Route route;                            ///< the recording rover
  std::vector<Route> other_rover_routes;  ///< one per tag-carrying rover
  ImuModelOptions imu;
  StereoCameraOptions camera;
  double ground_truth_rate_hz = 100.0;
  /// Wheel odometry model file (hil/config), empty: defaults.
  std::string wheels_config;
  /// GPIO edge model (trigger phase, lines, pulse widths); its camera rate is
  /// replaced by camera.rate_hz so the rate has one source of truth.
  GpioEdgeOptions gpio;
};

/// Loads a scenario file. Sensor config files it names are resolved relative
/// to `config_dir` (hil/config). Throws ConfigError naming file:line and key.
Scenario LoadScenario(const std::string& path, const std::string& config_dir);

/// Where scenarios and sensor configs live: $ROVER_SCENARIO_DIR and
/// $ROVER_SIM_CONFIG_DIR if set, else the source tree's hil/scenarios and
/// hil/config.
std::string DefaultScenarioDir();
std::string DefaultSimConfigDir();

/// The scenario files in `dir`, sorted by name.
std::vector<std::string> ListScenarioFiles(const std::string& dir);

/// Finds `name` ("short", "loop-100m", ...) in `dir`; throws
/// std::invalid_argument listing the available names if there is none.
std::string FindScenario(const std::string& dir, const std::string& name);

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_SCENARIO_SCENARIO_H_
