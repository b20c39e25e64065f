// roverd-sim: roverd's threads on the simulator's drivers (the simulator is
// one board profile), for `rover run --sim SCENARIO`.

#include <CLI/CLI.hpp>

#include <fstream>
#include <sstream>

#include <unistd.h>
#include <cstdio>
#include <exception>
#include <iostream>

#include "hil/sim/mission/sim_mission.h"

int main(int argc, char** argv) {
  CLI::App app{
      "roverd-sim: runs roverd (IMU loop with the local reference filter, camera + stereo VO,\n"
      "wheel odometry over CAN, flight log) on the simulator's drivers for a scenario, shows a\n"
      "status line, and ends with a summary against the simulator's ground truth whose last\n"
      "line is\n"
      "  RESULT scenario=… distance_m=… filter_final_err_pct=… slam_final_err_pct=…\n"
      "         imu_drops=… frame_drops=… loop_latency_us_p999=… rover=K log=PATH\n"
      "(slam_final_err_pct is nan here: rover-launch fills it from mapd's log; "
      "loop_latency_us_p999 is the\n"
      "IMU loop's sample-to-estimate latency in real time, the estimator step's wall time in\n"
      "lockstep, where sensor stamps are simulated time).\n"};
  rover::sim::MissionOptions options;
  bool realtime = false;
  app.add_option("--sim", options.scenario, "scenario (see `rover-sim list`)")
      ->capture_default_str();
  app.add_option("--rover", options.rover,
                 "which rover of a team scenario this process simulates: 0 drives `route`, k the "
                 "k-th of `other_rovers` (the others drive theirs in its view); its log is "
                 "mission-SCENARIO-ROVERNAME.mcap for k > 0")
      ->capture_default_str();
  app.add_option("--seed", options.seed, "world and sensor noise seed")->capture_default_str();
  app.add_flag("--realtime", realtime,
               "pace the sensors in real time (default: lockstep, as fast as the slowest thread)");
  app.add_option("--out", options.out_dir, "folder for the flight log")->capture_default_str();
  app.add_option("--max-duration-s", options.max_duration_s,
                 "stop after this much simulated time (default: the whole route)");
  app.add_option("--ipc", options.ipc_runtime_name,
                 "talk to mapd over iceoryx under this runtime name (RouDi must run; "
                 "rover-launch starts it)");
  std::string config;
  app.add_option("--config", config,
                 "board profile (YAML, e.g. firmware/config/sim.yaml): thread scheduling, health, "
                 "images, log service; its log folder is the default for --out");
  std::string result_file;
  app.add_option("--result-file", result_file,
                 "write the RESULT line to this file instead of standard output (rover-launch "
                 "adds the map's fields to it)");
  std::string images;
  app.add_option("--images", images,
                 "camera images in the log: none, thumbnails (cam0, ~188 px wide, 1 Hz; the "
                 "default) or full; overrides the board profile")
      ->check(CLI::IsMember({"none", "thumbnails", "full"}));
  CLI11_PARSE(app, argc, argv);
  try {
    if (!config.empty()) {
      options.board = rover::runtime::BoardConfig::LoadFile(config);
      const auto& log = options.board->log;
      options.images.mode =
          rover::roverd::ParseImageLogMode(std::string(rover::runtime::LogImagesName(log.images)));
      options.images.thumbnail_width_px = log.thumbnail_width_px;
      options.images.thumbnail_rate_hz = log.thumbnail_rate_hz;
      if (app.get_option("--out")->count() == 0) options.out_dir = log.folder;
    }
    if (!images.empty()) options.images.mode = rover::roverd::ParseImageLogMode(images);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "roverd-sim: %s\n", e.what());
    return 78;  // EX_CONFIG: systemd does not restart a bad configuration
  }
  options.lockstep = !realtime;
  const bool tty = isatty(STDERR_FILENO) != 0;
  options.status = [tty](const std::string& line) {
    if (tty) {
      std::fprintf(stderr, "\r\033[K%s", line.c_str());
    } else {
      std::fprintf(stderr, "%s\n", line.c_str());
    }
  };
  try {
    const rover::sim::MissionResult r = rover::sim::RunMission(options);
    if (tty) std::fprintf(stderr, "\r\033[K");
    std::ostringstream summary;
    rover::sim::PrintMissionSummary(r, summary);
    std::string text = summary.str();
    if (!result_file.empty()) {
      // The RESULT line is the summary's last.
      const std::size_t at = text.rfind("RESULT ");
      std::ofstream(result_file) << text.substr(at);
      text.erase(at);
    }
    std::cout << text << std::flush;
    return r.filter_initialised ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "\nroverd-sim: %s\n", e.what());
    return 2;
  }
}
