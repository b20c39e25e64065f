// roverd: the rover's real-time process, as flashed onto a board and started
// by rover-roverd.service. Reads the board profile, builds the drivers it
// names, and runs the IMU loop, camera, VO, CAN, mapd-link and health threads
// with the flight log and the HTTP log service until its sensors end or
// SIGTERM/SIGINT arrives; then prints what it did.
//
// Exit status: 0 after a run, 78 (EX_CONFIG) for an unusable board profile
// (systemd does not restart that: RestartPreventExitStatus=78), 2 when the
// run failed (RouDi absent, log not writable, ...).

#include <CLI/CLI.hpp>

#include <csignal>
#include <cstdio>
#include <ctime>
#include <exception>
#include <filesystem>
#include <iostream>
#include <memory>
#include <thread>

#include "firmware/roverd/hardware_board.h"
#include "firmware/roverd/replay_board.h"
#include "firmware/roverd/roverd_process.h"
#include "firmware/roverd/roverd_summary.h"
#include "firmware/runtime/board/board_config.h"

namespace {

volatile std::sig_atomic_t g_stop = 0;
void OnSignal(int) { g_stop = 1; }

// "roverd-20261121-134501.mcap": sortable, one per start.
std::string LogName() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[64];
  std::strftime(text, sizeof(text), "roverd-%Y%m%d-%H%M%S.mcap", &utc);
  return text;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "roverd: the rover's real-time process. Reads the board profile (--config), starts the\n"
      "drivers it names (profile hardware: the board's IMU, cameras and CAN bus; profile\n"
      "replay: a EuRoC-layout dataset; profile sim runs as roverd-sim), and runs the local "
      "reference filter on the IMU thread with stereo VO,\n"
      "wheel odometry, the flight log in log.folder, the health report, the mapd link over\n"
      "iceoryx and the HTTP log service, until the sensors end or SIGTERM/SIGINT.\n"};
  std::string config = rover::runtime::DefaultBoardConfigPath();
  bool no_ipc = false;
  app.add_option("--config", config, "board profile (YAML)")->capture_default_str();
  app.add_flag("--no-ipc", no_ipc, "run without RouDi and mapd");
  CLI11_PARSE(app, argc, argv);

  rover::runtime::BoardConfig board;
  std::unique_ptr<rover::roverd::ReplayBoard> replay;
  std::unique_ptr<rover::roverd::HardwareBoard> hardware;
  try {
    board = rover::runtime::BoardConfig::LoadFile(config);
    switch (board.board.profile) {
      case rover::runtime::BoardProfile::kReplay:
        replay = std::make_unique<rover::roverd::ReplayBoard>(*board.replay);
        break;
      case rover::runtime::BoardProfile::kHardware:
        hardware = std::make_unique<rover::roverd::HardwareBoard>(*board.hardware);
        break;
      case rover::runtime::BoardProfile::kSim:
        std::fprintf(stderr,
                     "roverd: %s: board.profile sim has no drivers in roverd (the simulator's "
                     "profile runs as roverd-sim); expected hardware or replay\n",
                     config.c_str());
        return 78;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "roverd: %s\n", e.what());
    return 78;
  }
  const std::string profile(rover::runtime::BoardProfileName(board.board.profile));
  try {
    rover::roverd::RoverdOptions options = replay ? replay->options() : hardware->options();
    rover::roverd::ApplyBoard(board, &options);

    rover::roverd::RoverdProcessOptions process;
    process.log_path = (std::filesystem::path(board.log.folder) / LogName()).string();
    process.metadata["board"] = {{"name", board.board.name},
                                 {"profile", profile},
                                 {"source", replay ? board.replay->dataset : "devices"},
                                 {"config", config}};
    if (!no_ipc) process.ipc_runtime_name = "roverd";
    process.roudi_wait = rover::Duration::FromSeconds(board.ipc.roudi_wait_s);
    process.images.mode = rover::roverd::ParseImageLogMode(
        std::string(rover::runtime::LogImagesName(board.log.images)));
    process.images.thumbnail_width_px = board.log.thumbnail_width_px;
    process.images.thumbnail_rate_hz = board.log.thumbnail_rate_hz;
    process.log_service = board.log_service;
    process.lock_memory = board.realtime.lock_memory;
    process.imu_thread = board.threads.imu;

    rover::roverd::RoverdProcess roverd(options, replay ? replay->drivers() : hardware->drivers(),
                                        process);
    std::signal(SIGTERM, OnSignal);
    std::signal(SIGINT, OnSignal);
    // Signals only set a flag; this relay turns it into Stop().
    std::atomic<bool> done{false};
    std::thread relay([&] {
      while (!done.load()) {
        if (g_stop != 0) roverd.Stop();
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
    });
    if (replay) {
      std::fprintf(stderr, "roverd: %s (%s) replaying %s, logging to %s\n",
                   board.board.name.c_str(), config.c_str(), board.replay->dataset.c_str(),
                   process.log_path.c_str());
    } else {
      std::fprintf(stderr, "roverd: %s (%s) on its devices, logging to %s\n%s",
                   board.board.name.c_str(), config.c_str(), process.log_path.c_str(),
                   hardware->description().c_str());
    }
    rover::roverd::RoverdProcessResult result;
    try {
      result = roverd.Run();
    } catch (...) {
      done.store(true);
      relay.join();
      throw;
    }
    done.store(true);
    relay.join();
    std::cout << "roverd " << board.board.name << ": " << result.stats.imu_samples
              << " IMU samples "
              << (replay ? "replayed from " + board.replay->dataset : std::string("from the IMU"))
              << "\n";
    rover::roverd::PrintRoverdStats(result.stats, result.mapd_link, std::cout);
    if (hardware) std::cout << hardware->DeviceReport();
    std::cout << "  log     " << process.log_path << " (" << result.log.written << " records, "
              << result.log.dropped << " dropped); replay it with `rover replay "
              << process.log_path << "`\n";
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "roverd: %s\n", e.what());
    return 2;
  }
}
