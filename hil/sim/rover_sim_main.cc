// rover-sim: the rover simulator's command-line front end.

#include <unistd.h>
#include <CLI/CLI.hpp>

#include <iostream>
#include <map>

#include "hil/sim/imu_mission.h"

int main(int argc, char** argv) {
  CLI::App app{
      "rover-sim: simulated rover sensors for software-in-the-loop runs.\n"
      "Sensor streams go through the same real-time flight-log path as on the rover."};
  app.require_subcommand(1);

  rover::sim::ImuMissionOptions options;
  std::string compression = "zstd";
  auto* imu = app.add_subcommand(
      "imu",
      "Drive a circuit with a simulated IMU at a real-time-paced thread and log it to MCAP\n"
      "(raw IMU on /imu, ground truth on /sim/ground_truth, log health on /rover/log_health)");
  imu->add_option("--out", options.output_path, "flight log to write (.mcap)")
      ->capture_default_str();
  imu->add_option("--duration-s", options.duration_s, "simulated time [s]")
      ->check(CLI::Range(0.1, 86400.0))
      ->capture_default_str();
  imu->add_option("--rate-hz", options.imu_rate_hz, "IMU sample rate [Hz]")
      ->check(CLI::Range(100.0, 1000.0))
      ->capture_default_str();
  imu->add_option("--seed", options.imu_errors.seed, "seed of the IMU error model")
      ->capture_default_str();
  imu->add_flag("--lockstep", options.lockstep,
                "run as fast as possible with simulated timestamps instead of real time");
  imu->add_option("--priority", options.imu_thread_priority,
                  "SCHED_FIFO priority of the IMU thread (0: normal scheduling)")
      ->check(CLI::Range(0, 99))
      ->capture_default_str();
  imu->add_option("--compression", compression, "chunk compression")
      ->check(CLI::IsMember({"zstd", "lz4", "none"}))
      ->capture_default_str();

  CLI11_PARSE(app, argc, argv);

  static const std::map<std::string, rover::log::Compression> kCodecs = {
      {"zstd", rover::log::Compression::kZstd},
      {"lz4", rover::log::Compression::kLz4},
      {"none", rover::log::Compression::kNone}};
  options.compression = kCodecs.at(compression);
  options.status_in_place = isatty(STDERR_FILENO) != 0;
  try {
    const rover::sim::ImuMissionResult result = rover::sim::RunImuMission(options, std::cerr);
    if (!result.realtime_priority && options.imu_thread_priority > 0) {
      std::cerr << "rover-sim: no permission for SCHED_FIFO " << options.imu_thread_priority
                << "; the IMU thread ran at normal priority (degraded timing)\n";
    }
    rover::sim::PrintImuMissionSummary(options, result, std::cout);
    return result.error.empty() ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << "rover-sim: " << e.what() << "\n";
    return 1;
  }
}
