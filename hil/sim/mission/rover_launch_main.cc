// rover-launch: the launcher of the simulated mission. Starts RouDi (unless
// one already runs), mapd and roverd-sim, restarts mapd whenever it dies
// (as systemd does on a board: Restart=always), and when roverd-sim is done
// stops mapd and the RouDi it started. With --evaluate-map it then scores
// the mission's map against the simulator's ground truth (rover-sim map)
// and ends with roverd-sim's RESULT line extended by the map's fields.
// Exits with roverd-sim's status.

#include <CLI/CLI.hpp>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <iostream>

#include "core/ipc/iceoryx_transport.h"
#include "firmware/runtime/board/board_config.h"
#include "firmware/runtime/process/child_process.h"
#include "hil/sim/experiments/map_command.h"
#include "hil/sim/experiments/team_evaluation.h"
#include "hil/sim/scenario/scenario.h"
#include "hil/sim/scenario/team_rovers.h"
#include "hil/sim/world/world.h"

namespace {

namespace fs = std::filesystem;
using rover::Duration;
using rover::Time;
using rover::runtime::ChildProcess;

volatile std::sig_atomic_t g_stop = 0;
void OnSignal(int) { g_stop = 1; }

void Say(const std::string& text) { std::fprintf(stderr, "rover-launch: %s\n", text.c_str()); }

// Scores the mission's map and prints the extended RESULT line. mapd's logs
// are those its processes (`mapd_pids`) wrote into `map_dir`.
void EvaluateMap(const std::string& roverd_result, const fs::path& map_dir,
                 const std::vector<int>& mapd_pids) {
  std::string line = roverd_result.substr(0, roverd_result.find('\n'));
  rover::sim::experiments::MapCommandOptions options;
  options.mission_log = rover::sim::experiments::ResultLineField(line, "log");
  for (const auto& entry : fs::directory_iterator(map_dir)) {
    const std::string name = entry.path().filename().string();
    for (const int pid : mapd_pids) {
      const std::string suffix = "-" + std::to_string(pid) + ".mcap";
      if (name.rfind("mapd-", 0) == 0 && name.size() > suffix.size() &&
          name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) {
        options.mapd_logs.push_back(entry.path().string());
      }
    }
  }
  std::sort(options.mapd_logs.begin(), options.mapd_logs.end());
  try {
    if (options.mission_log.empty()) throw std::runtime_error("roverd-sim gave no log= field");
    if (options.mapd_logs.empty())
      throw std::runtime_error("mapd wrote no log in " + map_dir.string());
    std::cout << "map (rover-sim map " << options.mission_log << "):\n";
    const rover::sim::experiments::MapResult r =
        rover::sim::experiments::EvaluateMission(options, std::cout);
    // roverd-sim cannot know the graph's result: mapd's log has it.
    const std::string slam_field = " slam_final_err_pct=";
    const std::size_t at = line.find(slam_field);
    if (at != std::string::npos) {
      const std::size_t begin = at + slam_field.size();
      const std::size_t end = line.find(' ', begin);
      char value[32];
      std::snprintf(value, sizeof(value), "%.4f", r.slam_final_error_pct);
      line.replace(begin, end - begin, std::isfinite(r.slam_final_error_pct) ? value : "nan");
    }
    std::cout << line << " " << rover::sim::experiments::MapResultFields(r) << "\n";
  } catch (const std::exception& e) {
    Say("map evaluation: " + std::string(e.what()));
    std::cout << line
              << " map_precision=nan map_recall=nan obstacle_precision=nan obstacle_recall=nan "
                 "submaps=0 submap_bytes_per_s=nan raw_stereo_bytes_per_s=nan loop_closures=0 "
                 "loop_closure_precision=nan matcher_ms_p50=nan graph_update_ms_p99=nan "
                 "frame_switch_nees=nan tag_detections=0 tag_factors=0 "
                 "tag_nees_in_bound_pct=nan tag_flips_claimed=0 slam_without_tags_err_pct=nan "
                 "team_factors=0 slam_alone_err_pct=nan\n";
  }
}

std::optional<ChildProcess> StartRouDi(const std::string& config, const fs::path& run_dir) {
  if (rover::ipc::IceoryxTransport::IsRouDiRunning()) {
    Say("a RouDi is already running; using it");
    return std::nullopt;
  }
  ChildProcess roudi = ChildProcess::Spawn({.argv = {"iox-roudi", "-c", config, "-l", "warning"},
                                            .output_file = (run_dir / "roudi.log").string()});
  const Time deadline = Time::Now() + Duration::Seconds(10);
  while (!rover::ipc::IceoryxTransport::IsRouDiRunning()) {
    if (const auto status = roudi.TryWait()) {
      throw std::runtime_error("iox-roudi " + status->Describe() + " during start-up; see " +
                               (run_dir / "roudi.log").string());
    }
    if (deadline < Time::Now()) {
      throw std::runtime_error("iox-roudi did not accept connections within 10 s; see " +
                               (run_dir / "roudi.log").string());
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  Say("RouDi started (pid " + std::to_string(roudi.pid()) + ")");
  return roudi;
}

// The value given to roverd-sim for `option` ("--sim short" or
// "--sim=short"), or `fallback`.
std::string RoverdArg(const std::vector<std::string>& args, const std::string& option,
                      const std::string& fallback) {
  for (std::size_t k = 0; k < args.size(); ++k) {
    if (args[k] == option && k + 1 < args.size()) return args[k + 1];
    if (args[k].rfind(option + "=", 0) == 0) return args[k].substr(option.size() + 1);
  }
  return fallback;
}

// Writes the mission world's tag markers for mapd (the site survey a real
// mission would have) and returns the file's path.
std::string WriteTagMarkers(const std::vector<std::string>& roverd_args, const fs::path& run_dir) {
  namespace sim = rover::sim;
  const std::string scenario_name = RoverdArg(roverd_args, "--sim", "short");
  const uint64_t seed = std::stoull(RoverdArg(roverd_args, "--seed", "1"));
  const sim::Scenario scenario = sim::LoadScenario(
      sim::FindScenario(sim::DefaultScenarioDir(), scenario_name), sim::DefaultSimConfigDir());
  const sim::World world = sim::World::Generate(scenario.world, seed);
  const fs::path path = run_dir / "tags.yaml";
  std::ofstream out(path);
  // Robot markers in each rover's body frame, as its filter knows it.
  const sim::TeamRovers team = sim::MakeTeamRovers(scenario, world);
  std::map<int, double> body_height_m;
  for (std::size_t k = 0; k < team.size(); ++k) {
    body_height_m[static_cast<int>(k)] = team.trajectories[k].options().body_height_m;
  }
  out << sim::TagMarkerFile(world, body_height_m);
  if (!out) throw std::runtime_error("cannot write " + path.string());
  std::size_t tags = 0;
  for (const sim::TagCarrier& c : world.carriers) tags += c.tags.size();
  Say("mapd looks for the world's " + std::to_string(tags) + " AprilTags (" + path.string() + ")");
  return path.string();
}

ChildProcess StartMapd(const std::vector<std::string>& argv, const fs::path& run_dir) {
  ChildProcess mapd = ChildProcess::Spawn({.argv = argv});
  std::ofstream(run_dir / "mapd.pid") << mapd.pid() << "\n";
  return mapd;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "rover-launch: runs the simulated mission as on a board: RouDi (iceoryx broker), mapd\n"
      "(mapping, restarted whenever it dies) and roverd-sim (roverd on the simulator's\n"
      "drivers). Arguments after `--` go to roverd-sim, e.g.\n"
      "  rover-launch --mapd build/dev/firmware/mapd/mapd \\\n"
      "               --roverd-sim build/dev/hil/sim/mission/roverd-sim -- --sim short\n"
      "mapd's pid is kept in RUN_DIR/mapd.pid, so a crash can be staged with\n"
      "  kill -9 $(cat RUN_DIR/mapd.pid)\n"
      "Exits with roverd-sim's status.\n"};
  std::string roverd_sim = "roverd-sim";
  std::string mapd = "mapd";
  std::string roudi_config = "firmware/config/roudi.toml";
  std::string run_dir = "build/mission/run";
  double restart_backoff_s = 1.0;
  bool no_mapd = false;
  std::vector<std::string> mapd_args;
  std::vector<std::string> roverd_args;
  app.add_option("--roverd-sim", roverd_sim, "roverd-sim executable")->capture_default_str();
  app.add_option("--mapd", mapd, "mapd executable")->capture_default_str();
  app.add_option("--mapd-arg", mapd_args, "extra argument for mapd (repeatable)");
  app.add_flag("--no-mapd", no_mapd, "run roverd-sim with the link but without mapd");
  bool no_tags = false;
  app.add_flag("--no-tags", no_tags,
               "mapd detects no AprilTags (by default it gets the simulated world's markers, "
               "written to RUN_DIR/tags.yaml, and adds landmark sightings to its pose graph)");
  app.add_option("--roudi-config", roudi_config, "RouDi TOML config")->capture_default_str();
  app.add_option("--run-dir", run_dir, "pid files and RouDi's log")->capture_default_str();
  app.add_option("--restart-backoff-s", restart_backoff_s, "wait before restarting mapd")
      ->capture_default_str();
  std::string config;
  app.add_option("--config", config,
                 "board profile for mapd and roverd-sim (and mapd's restart back-off)");
  std::string evaluate_map;
  app.add_option("--evaluate-map", evaluate_map,
                 "mapd writes its logs and map into this folder, and after the mission the map "
                 "is scored against the simulator's ground truth: the RESULT line gains "
                 "map_precision, map_recall, obstacle_precision, obstacle_recall, submaps, "
                 "submap_bytes_per_s and raw_stereo_bytes_per_s");
  app.add_option("roverd_args", roverd_args, "arguments for roverd-sim (after --)");
  CLI11_PARSE(app, argc, argv);
  std::signal(SIGTERM, OnSignal);
  std::signal(SIGINT, OnSignal);
  try {
    if (!config.empty()) {
      const auto board = rover::runtime::BoardConfig::LoadFile(config);
      if (app.get_option("--restart-backoff-s")->count() == 0) {
        restart_backoff_s = board.mapd.restart_backoff_s;
      }
      mapd_args.insert(mapd_args.begin(), {"--config", config});
      roverd_args.insert(roverd_args.begin(), {"--config", config});
    }
    fs::create_directories(run_dir);
    const fs::path result_file = fs::path(run_dir) / "roverd_result.txt";
    if (!evaluate_map.empty()) {
      fs::create_directories(evaluate_map);
      fs::remove(result_file);
      mapd_args.insert(mapd_args.end(), {"--out", evaluate_map});
      roverd_args.insert(roverd_args.end(), {"--result-file", result_file.string()});
    }
    if (!no_mapd && !no_tags) {
      mapd_args.insert(mapd_args.end(), {"--tags", WriteTagMarkers(roverd_args, run_dir)});
    }
    std::vector<int> mapd_pids;
    std::optional<ChildProcess> roudi = StartRouDi(roudi_config, run_dir);
    std::vector<std::string> mapd_argv = {mapd};
    mapd_argv.insert(mapd_argv.end(), mapd_args.begin(), mapd_args.end());
    std::optional<ChildProcess> mapd_process;
    if (!no_mapd) {
      mapd_process = StartMapd(mapd_argv, run_dir);
      mapd_pids.push_back(mapd_process->pid());
      Say("mapd started (pid " + std::to_string(mapd_process->pid()) + ")");
    }
    std::vector<std::string> roverd_argv = {roverd_sim, "--ipc", "roverd"};
    roverd_argv.insert(roverd_argv.end(), roverd_args.begin(), roverd_args.end());
    ChildProcess roverd = ChildProcess::Spawn({.argv = roverd_argv});
    int restarts = 0;
    std::optional<Time> restart_at;
    std::optional<rover::runtime::ExitStatus> roverd_status;
    while (!(roverd_status = roverd.TryWait())) {
      if (g_stop != 0) {
        Say("stopping on signal");
        roverd.Signal(SIGTERM);
        roverd_status = roverd.Terminate(Duration::Seconds(10));
        break;
      }
      if (mapd_process && !restart_at) {
        if (const auto status = mapd_process->TryWait()) {
          Say("mapd " + status->Describe() + "; restarting it in " +
              std::to_string(restart_backoff_s) + " s");
          restart_at = Time::Now() + Duration::FromSeconds(restart_backoff_s);
        }
      }
      if (restart_at && *restart_at < Time::Now()) {
        mapd_process = StartMapd(mapd_argv, run_dir);
        mapd_pids.push_back(mapd_process->pid());
        ++restarts;
        restart_at.reset();
        Say("mapd restarted (pid " + std::to_string(mapd_process->pid()) + ")");
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    if (mapd_process) {
      // mapd finishes its submap, composes and exports the map on SIGTERM.
      const auto status = mapd_process->Terminate(Duration::Seconds(60));
      Say("mapd stopped (" + status.Describe() + "), restarted " + std::to_string(restarts) +
          " times during the mission");
    }
    if (roudi) roudi->Terminate(Duration::Seconds(10));
    fs::remove(fs::path(run_dir) / "mapd.pid");
    if (!roverd_status->ok()) Say("roverd-sim " + roverd_status->Describe());
    if (!evaluate_map.empty()) {
      std::ifstream in(result_file);
      std::string roverd_result((std::istreambuf_iterator<char>(in)),
                                std::istreambuf_iterator<char>());
      if (roverd_result.empty()) {
        Say("roverd-sim wrote no RESULT line; no map evaluation");
      } else {
        EvaluateMap(roverd_result, evaluate_map, mapd_pids);
      }
    }
    return roverd_status->exited ? roverd_status->exit_code : 128 + roverd_status->signal;
  } catch (const std::exception& e) {
    Say(e.what());
    return 2;
  }
}
