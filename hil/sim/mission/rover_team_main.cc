// rover-team: the simulated team mission. Every rover of a team scenario runs
// its own full stack, as on separate boards: its own network namespace
// (joined to the others by veth pairs and a bridge, hil/bench/
// team_link_netns.sh), its own mount namespace with a private /dev/shm and
// /tmp (so its own RouDi), and in it rover-launch with RouDi, mapd (in the
// team: Cyclone DDS on the rover's interface, unicast to the others) and
// roverd-sim as that rover. When every rover is done it prints each rover's
// RESULT line and the team's (team_evaluation.h).

#include <CLI/CLI.hpp>

#include <csignal>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "firmware/runtime/process/child_process.h"
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

void Say(const std::string& text) { std::fprintf(stderr, "rover-team: %s\n", text.c_str()); }

// Runs a command to completion; throws naming it if it fails.
void Run(const std::vector<std::string>& argv, const fs::path& output) {
  ChildProcess p = ChildProcess::Spawn({.argv = argv, .output_file = output.string()});
  const auto status = p.WaitFor(Duration::Seconds(60));
  if (!status || !status->ok()) {
    std::string command;
    for (const std::string& a : argv) command += (command.empty() ? "" : " ") + a;
    throw std::runtime_error(command + ": " + (status ? status->Describe() : "timed out") +
                             "; see " + output.string());
  }
}

// The team file every rover's mapd reads: rover k is robot k, at
// 10.77.0.(k+1) on interface r(k+1) in namespace rover(k+1).
std::string TeamFile(const std::vector<std::string>& names, uint32_t domain_id,
                     double budget_bytes_per_s) {
  std::string s =
      "# Written by rover-team for this mission.\ndomain_id: " + std::to_string(domain_id) +
      "\nrobots:\n";
  for (std::size_t k = 0; k < names.size(); ++k) {
    const std::string i = std::to_string(k + 1);
    s += "  - {id: " + std::to_string(k) + ", name: " + names[k] + ", address: 10.77.0." + i +
         ", interface: r" + i + "}\n";
  }
  s += "link:\n  budget_bytes_per_s: " + std::to_string(budget_bytes_per_s) + "\n";
  return s;
}

// Run by `sh -c` in a rover's private mount namespace: a board of its own,
// whose RouDi's shared memory (/dev/shm) and sockets (/tmp) stay in here. The
// host's /tmp is hidden then, so the folders given before `--` (output,
// build, source) that lie under it are bound back in at the same paths.
// Arguments: the rover's number, the folders, --, the command.
constexpr const char* kPrivateBoard = R"(set -e
n=$1; shift
host=/run/rover-team/tmp-$n
mkdir -p "$host"
mount --bind /tmp "$host"
mount -t tmpfs rover-shm /dev/shm
mount -t tmpfs rover-tmp /tmp
while [ "$1" != "--" ]; do
  case "$1" in
    /tmp/*) mkdir -p "$1"; mount --bind "$host/${1#/tmp/}" "$1" ;;
  esac
  shift
done
shift
exec "$@")";

// The last RESULT line of a rover's output ("" if none).
std::string LastResultLine(const fs::path& path) {
  std::ifstream in(path);
  std::string line;
  std::string result;
  while (std::getline(in, line)) {
    if (line.rfind("RESULT ", 0) == 0) result = line;
  }
  return result;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "rover-team: runs a team scenario (e.g. two-rovers) with one full stack per rover, each\n"
      "in its own network and mount namespace (own RouDi), the team's link between them\n"
      "(veth + bridge; shape it with hil/bench/team_link_netns.sh shape while it runs), and\n"
      "ends with one RESULT line per rover and one for the team. Needs root (namespaces).\n"
      "  rover-team --bin build/dev --out build/team -- --sim two-rovers --seed 1\n"};
  std::string bin = "build/dev";
  std::string source = ".";
  std::string out = "build/team";
  uint32_t domain_id = 0;
  double budget_bytes_per_s = 30000.0;
  std::vector<std::string> roverd_args;
  app.add_option("--bin", bin, "the build tree (rover-launch, mapd, roverd-sim)")
      ->capture_default_str();
  app.add_option("--source", source, "the source tree (configs, scripts)")->capture_default_str();
  app.add_option("--out", out, "one folder per rover under this, and the team file")
      ->capture_default_str();
  app.add_option("--domain-id", domain_id, "the team's DDS domain")->capture_default_str();
  app.add_option("--budget-bytes-per-s", budget_bytes_per_s,
                 "what each rover may send on the link, on average")
      ->capture_default_str();
  bool evaluate_only = false;
  app.add_flag("--evaluate-only", evaluate_only,
               "run nothing: score the team mission already in --out (after a change to the "
               "evaluation, or to look again)");
  app.add_option("roverd_args", roverd_args,
                 "arguments for every rover's roverd-sim (after --): --sim, --seed, ...");
  CLI11_PARSE(app, argc, argv);
  std::signal(SIGTERM, OnSignal);
  std::signal(SIGINT, OnSignal);
  namespace sim = rover::sim;
  std::string scenario_name = "two-rovers";
  uint64_t seed = 1;
  for (std::size_t k = 0; k + 1 < roverd_args.size(); ++k) {
    if (roverd_args[k] == "--sim") scenario_name = roverd_args[k + 1];
    if (roverd_args[k] == "--seed") seed = std::stoull(roverd_args[k + 1]);
  }
  const fs::path netns = fs::path(source) / "hil/bench/team_link_netns.sh";
  std::size_t n = 0;
  try {
    const sim::Scenario scenario = sim::LoadScenario(
        sim::FindScenario(sim::DefaultScenarioDir(), scenario_name), sim::DefaultSimConfigDir());
    const sim::World world = sim::World::Generate(scenario.world, seed);
    const sim::TeamRovers team = sim::MakeTeamRovers(scenario, world);
    n = team.size();
    if (n < 2) throw std::invalid_argument("scenario " + scenario_name + " has one rover");
    std::vector<fs::path> outputs;
    std::vector<std::optional<rover::runtime::ExitStatus>> status(n);
    if (evaluate_only) {
      for (std::size_t k = 0; k < n; ++k) {
        outputs.push_back(fs::absolute(fs::path(out) / team.names[k]) / "launch.txt");
        status[k] = rover::runtime::ExitStatus{.exited = true, .exit_code = 0};
      }
    } else {
      fs::create_directories(out);
      const fs::path team_file = fs::absolute(fs::path(out) / "team.yaml");
      std::ofstream(team_file) << TeamFile(team.names, domain_id, budget_bytes_per_s);
      // Leftovers of an earlier run that was killed.
      ChildProcess::Spawn({.argv = {netns.string(), "down", std::to_string(n)},
                           .output_file = (fs::path(out) / "netns.txt").string()})
          .WaitFor(Duration::Seconds(30));
      Run({netns.string(), "up", std::to_string(n)}, fs::path(out) / "netns.txt");
      Say("team link up: " + std::to_string(n) + " rovers in namespaces rover1..rover" +
          std::to_string(n) + " (10.77.0.1..), team file " + team_file.string());

      std::vector<ChildProcess> rovers;
      for (std::size_t k = 0; k < n; ++k) {
        const fs::path dir = fs::absolute(fs::path(out) / team.names[k]);
        fs::create_directories(dir);
        outputs.push_back(dir / "launch.txt");
        fs::remove(outputs.back());
        std::vector<std::string> command = {
            "ip", "netns", "exec", "rover" + std::to_string(k + 1), "unshare", "--mount",
            "--propagation", "private", "--", "sh", "-c", kPrivateBoard, "sh",
            std::to_string(k + 1), fs::absolute(out).string(), fs::absolute(bin).string(),
            fs::absolute(source).string(), "--",
            fs::absolute(fs::path(bin) / "hil/sim/mission/rover-launch").string(), "--roverd-sim",
            fs::absolute(fs::path(bin) / "hil/sim/mission/roverd-sim").string(), "--mapd",
            fs::absolute(fs::path(bin) / "firmware/mapd/mapd").string(), "--roudi-config",
            fs::absolute(fs::path(source) / "firmware/config/roudi.toml").string(), "--config",
            fs::absolute(fs::path(source) / "firmware/config/sim.yaml").string(),
            "--mapd-arg=--team", "--mapd-arg=" + team_file.string(), "--mapd-arg=--robot-id",
            "--mapd-arg=" + std::to_string(k),
            // Not a repeatable option right before "--": CLI11 then takes
            // what follows as unexpected arguments.
            "--evaluate-map", dir.string(), "--run-dir", (dir / "run").string(), "--"};
        command.insert(command.end(), roverd_args.begin(), roverd_args.end());
        command.insert(command.end(), {"--rover", std::to_string(k), "--out", dir.string()});
        rovers.push_back(
            ChildProcess::Spawn({.argv = command, .output_file = outputs.back().string()}));
        Say(team.names[k] + " started (pid " + std::to_string(rovers.back().pid()) + "), output " +
            outputs.back().string());
      }
      const Time start = Time::Now();
      Time next_status = start + Duration::Seconds(15);
      std::size_t running = n;
      while (running > 0) {
        for (std::size_t k = 0; k < n; ++k) {
          if (status[k] || !(status[k] = rovers[k].TryWait())) continue;
          --running;
          Say(team.names[k] + " done (" + status[k]->Describe() + ") after " +
              std::to_string(static_cast<int>((Time::Now() - start).ToSeconds())) + " s");
        }
        if (g_stop != 0) {
          Say("stopping on signal");
          for (std::size_t k = 0; k < n; ++k) {
            if (!status[k]) status[k] = rovers[k].Terminate(Duration::Seconds(90));
          }
          break;
        }
        if (next_status < Time::Now()) {
          next_status = Time::Now() + Duration::Seconds(15);
          Say(std::to_string(running) + " of " + std::to_string(n) + " rovers still running, " +
              std::to_string(static_cast<int>((Time::Now() - start).ToSeconds())) + " s");
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
      }
      Run({netns.string(), "down", std::to_string(n)}, fs::path(out) / "netns.txt");
    }

    std::vector<sim::experiments::TeamRoverRun> runs;
    bool ok = true;
    for (std::size_t k = 0; k < n; ++k) {
      sim::experiments::TeamRoverRun r;
      r.name = team.names[k];
      r.robot = static_cast<int>(k);
      r.folder = (fs::path(out) / team.names[k]).string();
      r.result_line = LastResultLine(outputs[k]);
      if (r.result_line.empty()) {
        Say(team.names[k] + " printed no RESULT line; see " + outputs[k].string());
        ok = false;
      }
      ok = ok && status[k] && status[k]->ok();
      runs.push_back(std::move(r));
    }
    const sim::experiments::TeamResult result =
        sim::experiments::EvaluateTeam(scenario_name, runs, std::cout);
    for (const std::string& line : result.rover_lines) std::cout << line << "\n";
    std::cout << result.team_line << "\n";
    return ok ? 0 : 1;
  } catch (const std::exception& e) {
    Say(e.what());
    if (n > 0) {
      ChildProcess::Spawn({.argv = {netns.string(), "down", std::to_string(n)},
                           .output_file = (fs::path(out) / "netns.txt").string()})
          .WaitFor(Duration::Seconds(30));
    }
    return 2;
  }
}
