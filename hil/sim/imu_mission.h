#ifndef ROVER_HIL_SIM_IMU_MISSION_H_
#define ROVER_HIL_SIM_IMU_MISSION_H_

// The early mission slice: the simulated rover drives survey loops over a
// generated terrain, and a simulated IMU thread samples it and drives the
// real-time flight-log path (LogChannel::Log from a paced loop) while the
// writer thread produces a crash-safe MCAP file. It stands in for roverd
// until the estimator and the full simulator land.

#include <cstdint>
#include <ostream>
#include <string>

#include "core/log/mcap/compression.h"
#include "hil/sim/motion/rover_trajectory.h"
#include "hil/sim/sensors/imu_model.h"

namespace rover::sim {

struct ImuMissionOptions {
  std::string output_path = "mission.mcap";
  double duration_s = 60.0;
  double ground_truth_rate_hz = 50.0;
  /// Real time paces the loop with clock_nanosleep; lockstep runs as fast as
  /// possible with simulated timestamps (same output for the same seed).
  bool lockstep = false;
  /// Try SCHED_FIFO at this priority for the IMU thread (0: don't).
  int imu_thread_priority = 80;
  /// Rewrite the status line in place (a terminal) instead of one line per second.
  bool status_in_place = false;
  log::Compression compression = log::Compression::kZstd;
  int zstd_level = 1;
  /// IMU rate and errors; rover-sim loads them from DefaultImuConfigPath().
  ImuModelOptions imu;
  RoverTrajectoryOptions motion;
  uint64_t terrain_seed = 1;
  double terrain_size_m = 32.0;  ///< side of the generated square site
  double loop_size_x_m = 10.0;   ///< survey rectangle, centred on the site
  double loop_size_y_m = 6.0;
};

/// The MTi-10-class IMU parameter file shipped in hil/config/.
std::string DefaultImuConfigPath();

/// What the mission did, for the summary.
struct ImuMissionResult {
  uint64_t imu_samples = 0;
  uint64_t records_logged = 0;
  uint64_t records_written = 0;
  uint64_t records_dropped = 0;
  uint64_t file_bytes = 0;
  uint64_t chunks = 0;
  double wall_time_s = 0.0;
  double distance_m = 0.0;
  bool realtime_priority = false;
  double log_call_ns_p50 = 0.0;  ///< cost of LogChannel::Log() on the IMU thread
  double log_call_ns_p99 = 0.0;
  double log_call_ns_max = 0.0;
  double tick_lateness_us_p99 = 0.0;  ///< real-time mode: wake-up lateness of the IMU loop
  std::string error;
};

/// Runs the mission, printing a live status line to `status` once a second.
ImuMissionResult RunImuMission(const ImuMissionOptions& options, std::ostream& status);

/// Prints the end-of-mission summary.
void PrintImuMissionSummary(const ImuMissionOptions& options, const ImuMissionResult& result,
                            std::ostream& out);

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_IMU_MISSION_H_
