// rover-sim: the rover simulator's command-line front end.

#include <unistd.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <iostream>
#include <map>
#include <vector>

#include <cstdio>
#include <filesystem>

#include "drivers/can/socket_can_bus.h"
#include "hil/sim/dataset/dataset_generator.h"
#include "hil/sim/devices/simulated_mti.h"
#include "hil/sim/experiments/filter_command.h"
#include "hil/sim/experiments/loop_command.h"
#include "hil/sim/experiments/map_command.h"
#include "hil/sim/experiments/nees_command.h"
#include "hil/sim/experiments/terrain_command.h"
#include "hil/sim/imu_mission.h"
#include "hil/sim/live/sim_can_bus.h"
#include "hil/sim/scenario/scenario.h"
#include "hil/sim/sensors/imu_model.h"

namespace {

int RunList(std::ostream& out) {
  const std::string dir = rover::sim::DefaultScenarioDir();
  const auto files = rover::sim::ListScenarioFiles(dir);
  if (files.empty()) {
    std::cerr << "rover-sim list: no scenarios in " << dir << " (set ROVER_SCENARIO_DIR)\n";
    return 1;
  }
  for (const std::string& file : files) {
    const rover::sim::Scenario s =
        rover::sim::LoadScenario(file, rover::sim::DefaultSimConfigDir());
    char line[256];
    std::snprintf(line, sizeof line, "%-12s %s\n", s.name.c_str(), s.description.c_str());
    out << line;
  }
  return 0;
}

struct GenerateArgs {
  std::string scenario;
  uint64_t seed = 1;
  std::string out_dir;
  double max_duration_s = 0.0;
};

int RunGenerate(const GenerateArgs& args) {
  const std::string path =
      rover::sim::FindScenario(rover::sim::DefaultScenarioDir(), args.scenario);
  const rover::sim::Scenario scenario =
      rover::sim::LoadScenario(path, rover::sim::DefaultSimConfigDir());
  rover::sim::GenerateOptions options;
  options.seed = args.seed;
  options.out_dir = args.out_dir;
  options.max_duration_s = args.max_duration_s;
  const bool tty = isatty(STDERR_FILENO) != 0;
  const rover::Time start = rover::Time::Now();
  int last_decile = -1;
  options.progress = [&](double fraction, double sim_time_s) {
    const double elapsed_s = (rover::Time::Now() - start).ToSeconds();
    const double eta_s = fraction > 0 ? elapsed_s * (1.0 - fraction) / fraction : 0.0;
    const int decile = static_cast<int>(fraction * 10.0);
    if (!tty && decile == last_decile) return;
    last_decile = decile;
    std::fprintf(stderr, "%s[%3.0f%%] sim %7.1f s, wall %6.1f s, ETA %5.0f s%s", tty ? "\r" : "",
                 100.0 * fraction, sim_time_s, elapsed_s, eta_s, tty ? "" : "\n");
  };
  std::cerr << "rover-sim: generating '" << scenario.name << "' (seed " << args.seed << ") into "
            << args.out_dir << "\n";
  const rover::sim::GenerateResult r = rover::sim::GenerateDataset(scenario, options);
  if (tty) std::cerr << "\n";
  std::printf(
      "dataset %s\n  scenario:    %s, seed %llu\n  simulated:   %.1f s, %.1f m driven\n"
      "  imu:         %llu samples\n  stereo:      %llu pairs (%s)\n  can:         %llu frames\n"
      "  gpio:        %llu edges\n  rovers:      %zu dataset(s)\n  wall time:   %.1f s (world %.1f "
      "s, render %.1f s, write "
      "%.1f s), %.2fx real time\n",
      args.out_dir.c_str(), scenario.name.c_str(), static_cast<unsigned long long>(args.seed),
      r.sim_duration_s, r.distance_m, static_cast<unsigned long long>(r.imu_samples),
      static_cast<unsigned long long>(r.stereo_frames), r.gl_renderer.c_str(),
      static_cast<unsigned long long>(r.can_frames), static_cast<unsigned long long>(r.gpio_edges),
      r.rover_datasets, r.wall_time_s, r.world_time_s, r.render_time_s, r.write_time_s,
      r.sim_duration_s / std::max(r.wall_time_s, 1e-9));
  return 0;
}

struct CanArgs {
  std::string scenario;
  std::string interface;
  uint64_t seed = 1;
  double max_duration_s = 0.0;
  bool lockstep = false;
};

// Puts the scenario's wheel-drive frames (SYNC, TPDO1, heartbeats) on a real
// SocketCAN interface, at their times.
int RunCan(const CanArgs& args) {
  const rover::sim::Scenario scenario = rover::sim::LoadScenario(
      rover::sim::FindScenario(rover::sim::DefaultScenarioDir(), args.scenario),
      rover::sim::DefaultSimConfigDir());
  rover::drivers::SocketCanBus bus(args.interface);  // fails early, before the world is built
  const rover::sim::World world = rover::sim::World::Generate(scenario.world, args.seed);
  const rover::sim::RoverTrajectory trajectory(scenario.route, world.terrain);
  const double duration_s = args.max_duration_s > 0
                                ? std::min(args.max_duration_s, trajectory.duration_s())
                                : trajectory.duration_s();
  const rover::Time start = rover::Time::Now();
  const rover::drivers::ReplayClock clock(!args.lockstep, start);
  rover::sim::WheelOdometryModelOptions wheels;
  if (!scenario.wheels_config.empty()) {
    wheels = rover::sim::WheelOdometryModelOptions::LoadFile(scenario.wheels_config);
  }
  rover::sim::SimWheelCanBus source(wheels, trajectory, world.terrain, clock, start,
                                    start + rover::Duration::FromSeconds(duration_s));
  rover::drivers::CanFrame frame;
  uint64_t sent = 0;
  while (source.Receive(&frame, rover::Duration::Seconds(1)) !=
         rover::drivers::ReadStatus::kEndOfStream) {
    if (bus.Send(frame)) ++sent;
  }
  std::printf("sent %llu frames of '%s' to %s (%llu refused by the kernel)\n",
              static_cast<unsigned long long>(sent), scenario.name.c_str(), args.interface.c_str(),
              static_cast<unsigned long long>(bus.stats().send_failures));
  return bus.stats().send_failures == 0 ? 0 : 1;
}

struct MtiArgs {
  std::string scenario;
  std::string link;
  uint64_t seed = 1;
  double max_duration_s = 0.0;
  double wait_s = 60.0;
};

// A simulated Xsens MTi on a pty pair (hil/sim/devices) streaming the
// simulator's IMU along a scenario's route, for roverd's Xsens driver on the
// HIL bench: the driver configures it like the real device, then it streams
// MTData2 for the route's duration (or --max-duration-s) and goes quiet.
int RunMti(const MtiArgs& args) {
  namespace sim = rover::sim;
  const sim::Scenario scenario = sim::LoadScenario(
      sim::FindScenario(sim::DefaultScenarioDir(), args.scenario), sim::DefaultSimConfigDir());
  const sim::World world = sim::World::Generate(scenario.world, args.seed);
  const sim::RoverTrajectory trajectory(scenario.route, world.terrain);
  const double duration_s = args.max_duration_s > 0
                                ? std::min(args.max_duration_s, trajectory.duration_s())
                                : trajectory.duration_s();
  sim::ImuModelOptions imu = scenario.imu;
  imu.seed = scenario.imu.seed ^ (args.seed * 0x9E3779B97F4A7C15ULL);  // as `generate` seeds it
  sim::ImuModel model(imu, rover::Time::Zero());
  sim::SimulatedMtiOptions options;
  options.seed = args.seed;
  options.packet_source = [&](uint64_t, int) {
    // One model sample per packet, in order: the route's IMU at the model's
    // rate (the driver must configure the scenario's rate, checked below).
    const rover::drivers::ImuSample s = model.Next(trajectory);
    rover::drivers::MtData2Packet p;
    for (int i = 0; i < 3; ++i) {
      p.acceleration_m_s2[static_cast<std::size_t>(i)] =
          static_cast<float>(s.linear_acceleration_m_s2[i]);
      p.rate_of_turn_rad_s[static_cast<std::size_t>(i)] =
          static_cast<float>(s.angular_velocity_rad_s[i]);
    }
    return p;
  };
  sim::SimulatedMti mti(options);
  std::error_code ignored;
  std::filesystem::remove(args.link, ignored);
  std::filesystem::create_symlink(mti.port(), args.link);
  std::printf(
      "simulated MTi on %s (%s), scenario '%s' (%.1f s of IMU at %.0f Hz); waiting for "
      "the driver to configure it\n",
      mti.port().c_str(), args.link.c_str(), scenario.name.c_str(), duration_s, imu.rate_hz);
  std::fflush(stdout);
  const rover::Time wait_end = rover::Time::Now() + rover::Duration::FromSeconds(args.wait_s);
  while (!mti.measuring() && rover::Time::Now() < wait_end) usleep(10'000);
  int status = 0;
  if (!mti.measuring()) {
    std::fprintf(stderr, "rover-sim mti: no driver configured the device within %.0f s\n",
                 args.wait_s);
    status = 1;
  } else if (std::abs(mti.rate_hz() - imu.rate_hz) > 0.5) {
    std::fprintf(stderr, "rover-sim mti: the driver configured %d Hz; scenario '%s' has %.0f Hz\n",
                 mti.rate_hz(), scenario.name.c_str(), imu.rate_hz);
    status = 1;
  } else {
    const rover::Time end = rover::Time::Now() + rover::Duration::FromSeconds(duration_s);
    while (rover::Time::Now() < end) usleep(20'000);
    mti.StopStreaming();
    usleep(500'000);  // let the reader drain the pty
  }
  const sim::SimulatedMtiStats stats = mti.stats();
  std::printf("sent %llu MTData2 packets of '%s' on %s\n",
              static_cast<unsigned long long>(stats.packets), scenario.name.c_str(),
              args.link.c_str());
  std::filesystem::remove(args.link, ignored);
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "rover-sim: simulated rover sensors for software-in-the-loop runs, and the experiments\n"
      "that score the software against the simulator's ground truth (filter: the local\n"
      "reference filter's accuracy, nees: its Monte Carlo consistency, map: a simulated\n"
      "mission's map).\n"
      "Sensor streams go through the same real-time flight-log path as on the rover."};
  app.require_subcommand(1);

  rover::sim::ImuMissionOptions options;
  std::string compression = "zstd";
  std::string imu_config = rover::sim::DefaultImuConfigPath();
  double imu_rate_hz = 0.0;
  uint64_t imu_seed = 0;
  auto* imu = app.add_subcommand(
      "imu",
      "Drive survey loops over a generated terrain with a simulated IMU at a real-time-paced\n"
      "thread and log it to MCAP (raw IMU on /imu, ground truth on /sim/ground_truth, log\n"
      "health on /rover/log_health)");
  imu->add_option("--out", options.output_path, "flight log to write (.mcap)")
      ->capture_default_str();
  imu->add_option("--duration-s", options.duration_s, "simulated time [s]")
      ->check(CLI::Range(0.1, 86400.0))
      ->capture_default_str();
  imu->add_option("--imu-config", imu_config, "IMU parameter file (YAML)")->capture_default_str();
  auto* rate_option =
      imu->add_option("--rate-hz", imu_rate_hz, "IMU sample rate [Hz] (default: the config's)")
          ->check(CLI::Range(100.0, 1000.0));
  auto* seed_option =
      imu->add_option("--seed", imu_seed, "seed of the IMU error model (default: the config's)");
  imu->add_option("--terrain-seed", options.terrain_seed, "seed of the generated terrain")
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

  auto* list = app.add_subcommand("list", "Print the scenarios that `generate` accepts");

  GenerateArgs generate_args;
  auto* generate = app.add_subcommand(
      "generate",
      "Write a scenario as an EuRoC-layout dataset (IMU, stereo PNGs, ground truth, sensor.yaml,\n"
      "plus depth, wheel odometry, CAN frames, GPIO edges, tag poses and the world's ground "
      "truth)");
  generate->add_option("--scenario", generate_args.scenario, "scenario name (see `rover-sim list`)")
      ->required();
  generate->add_option("--seed", generate_args.seed, "world and sensor noise seed")
      ->capture_default_str();
  generate->add_option("--out", generate_args.out_dir, "output folder (must not hold a mav0/)")
      ->required();
  generate
      ->add_option("--max-duration-s", generate_args.max_duration_s,
                   "stop after this much simulated time (default: the whole route)")
      ->check(CLI::PositiveNumber);

  CanArgs can_args;
  auto* can = app.add_subcommand(
      "can", "Put a scenario's wheel-drive CANopen frames on a SocketCAN interface (e.g. vcan0)");
  can->add_option("--scenario", can_args.scenario, "scenario name")->required();
  can->add_option("--interface", can_args.interface, "SocketCAN interface")->required();
  can->add_option("--seed", can_args.seed, "world seed")->capture_default_str();
  can->add_option("--max-duration-s", can_args.max_duration_s, "stop after this long")
      ->check(CLI::PositiveNumber);
  can->add_flag("--lockstep", can_args.lockstep, "send as fast as possible, not in real time");

  MtiArgs mti_args;
  auto* mti = app.add_subcommand(
      "mti",
      "Simulate an Xsens MTi on a pty pair: answers the Xbus configuration, then streams the "
      "scenario's IMU as MTData2 (for roverd's Xsens driver on the HIL bench)");
  mti->add_option("--scenario", mti_args.scenario, "scenario name")->required();
  mti->add_option("--link", mti_args.link, "symlink created to the pty's device side")->required();
  mti->add_option("--seed", mti_args.seed, "world and IMU seed")->capture_default_str();
  mti->add_option("--max-duration-s", mti_args.max_duration_s, "stream at most this long")
      ->check(CLI::PositiveNumber);
  mti->add_option("--wait-s", mti_args.wait_s, "give up when no driver configures it this long")
      ->capture_default_str();

  // The experiments, one line each (hil/sim/experiments/*_command.{h,cc}).
  namespace experiments = rover::sim::experiments;
  const std::vector<rover::cli::Subcommand> experiment_commands = {
      experiments::AddFilterCommand(app),  experiments::AddNeesCommand(app),
      experiments::AddMapCommand(app),     experiments::AddLoopCommand(app),
      experiments::AddTerrainCommand(app),
  };

  CLI11_PARSE(app, argc, argv);

  for (const rover::cli::Subcommand& s : experiment_commands) {
    if (s.app->parsed()) return s.run();
  }
  try {
    if (*mti) return RunMti(mti_args);
    if (*can) return RunCan(can_args);
    if (*list) return RunList(std::cout);
    if (*generate) return RunGenerate(generate_args);
  } catch (const std::exception& e) {
    std::cerr << "rover-sim: " << e.what() << "\n";
    return 2;
  }

  static const std::map<std::string, rover::log::Compression> kCodecs = {
      {"zstd", rover::log::Compression::kZstd},
      {"lz4", rover::log::Compression::kLz4},
      {"none", rover::log::Compression::kNone}};
  options.compression = kCodecs.at(compression);
  options.status_in_place = isatty(STDERR_FILENO) != 0;
  try {
    options.imu = rover::sim::ImuModelOptions::LoadFile(imu_config);
    if (rate_option->count() > 0) options.imu.rate_hz = imu_rate_hz;
    if (seed_option->count() > 0) options.imu.seed = imu_seed;
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
