#ifndef ROVER_HIL_SIM_MISSION_SIM_MISSION_H_
#define ROVER_HIL_SIM_MISSION_SIM_MISSION_H_

// The main job: roverd's threads (firmware/roverd) on the simulator's
// drivers (IMU, rendered stereo pair, wheel drives on CAN) for a scenario,
// in real time or lockstep, writing the flight log, with a live status line
// and a summary scored against the simulator's ground truth.

#include <cstddef>
#include <functional>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "core/calib/camera_model.h"
#include "firmware/roverd/roverd.h"
#include "firmware/runtime/board/board_config.h"
#include "hil/sim/render/stereo_camera.h"

namespace rover::sim {

struct MissionOptions {
  std::string scenario = "short";
  /// Which rover of a team scenario this mission simulates: 0 drives the
  /// scenario's `route`, k > 0 the k-th of its `other_rovers` (see
  /// team_rovers.h). The other rovers drive their routes in its camera's view.
  std::size_t rover = 0;
  uint64_t seed = 1;
  bool lockstep = true;
  std::string out_dir = "build/mission";
  double max_duration_s = 0.0;  ///< 0: the simulated rover's whole route
  /// Connect to RouDi and talk to mapd (estimates, stereo pairs and frame
  /// switches out, frame-switch requests in) under this iceoryx runtime
  /// name; empty: run alone.
  std::string ipc_runtime_name;
  /// Fault injection: the cameras (or the CAN bus) go silent for good this
  /// many simulated seconds into the mission (0: never). The simulator's
  /// drivers then report the end of their stream, which roverd treats as a
  /// lost sensor.
  double camera_loss_at_s = 0.0;
  double can_loss_at_s = 0.0;
  /// Camera images in the log (thumbnails by default).
  roverd::ImageLogOptions images;
  /// The board profile (firmware/config/sim.yaml): thread scheduling,
  /// health, images, the log service. Absent: the built-in defaults.
  std::optional<runtime::BoardConfig> board;
  /// Called about once per second of wall time with one status line.
  std::function<void(const std::string& line)> status;
};

struct MissionResult {
  std::string scenario;
  std::size_t rover = 0;   ///< MissionOptions::rover
  std::string rover_name;  ///< its name in the world ("rover_a", "rover_b", ...)
  /// The simulated rover's true body position at the mission's start, world frame.
  Eigen::Vector3d p_world_body_start_m = Eigen::Vector3d::Zero();
  std::string log_path;
  double sim_duration_s = 0.0;
  double wall_time_s = 0.0;
  double distance_m = 0.0;  ///< horizontal distance between filter start and end
  /// |p_true - p| at the end in the filter's frame 0 (defined by the true
  /// pose at its initialisation; roverd switches no frames without mapd).
  double filter_final_error_m = 0.0;
  double filter_final_error_pct = 0.0;
  bool filter_initialised = false;
  roverd::RoverdStats stats;
  bool ipc = false;
  roverd::MapdLinkStats mapd_link;
  uint64_t frame_switches = 0;
  int log_service_port = 0;  ///< 0: no log service
  uint64_t log_records = 0;
  uint64_t log_drops = 0;
};

/// Runs the mission. Throws on bad options or an unusable set-up (naming it);
/// std::invalid_argument naming the scenario and its number of rovers when
/// options.rover is not one of them.
MissionResult RunMission(const MissionOptions& options);

/// The flight log's file name: mission-<scenario>.mcap for rover 0,
/// mission-<scenario>-<rover name>.mcap for the others.
std::string MissionLogName(const std::string& scenario, std::size_t rover,
                           const std::string& rover_name);

/// The summary, ending with the RESULT line of the command-line contract.
void PrintMissionSummary(const MissionResult& result, std::ostream& out);

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_MISSION_SIM_MISSION_H_
