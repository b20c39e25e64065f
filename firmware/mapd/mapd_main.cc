// mapd: the mapping process. Connects to RouDi, follows roverd's estimates,
// stereo pairs and frame switches, and asks for a new submap when the
// current one is done. Runs until SIGTERM/SIGINT; prints its submaps then.

#include <CLI/CLI.hpp>

#include <malloc.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <ctime>
#include <exception>
#include <filesystem>
#include <thread>

#include "core/ipc/iceoryx_transport.h"
#include "core/link/dds/dds_link.h"
#include "firmware/mapd/mapd.h"
#include "firmware/mapd/team_config.h"
#include "firmware/runtime/board/board_config.h"
#include "firmware/runtime/health/systemd_notifier.h"
#include "mapping/tags/tag_observer.h"

namespace {

volatile std::sig_atomic_t g_stop = 0;
void OnSignal(int) { g_stop = 1; }

// "mapd-20261121-134501-4711": sortable, one per start (a restart within
// the same second differs by pid).
std::string LogStem() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[64];
  std::strftime(text, sizeof(text), "mapd-%Y%m%d-%H%M%S", &utc);
  return std::string(text) + "-" + std::to_string(::getpid());
}

}  // namespace

int main(int argc, char** argv) {
  // A fixed mmap threshold. glibc otherwise raises it each time a mapped
  // block is freed (up to 32 MB), after which the loop threads' megabyte
  // match data and ICP buffers come from the malloc arenas, whose
  // fragmentation keeps their pages: mapd's footprint then creeps up over a
  // long mission. Fixed, blocks this large are mapped and returned whole.
  ::mallopt(M_MMAP_THRESHOLD, 256 * 1024);
  // One malloc arena for all of mapd's threads. glibc gives each thread that
  // allocates its own arena (up to 8 per core); the mapping loop, the two
  // loop-closure threads and the graph thread then each keep the high-water
  // mark of their own transients, and the matcher's, which only appears
  // once the rover revisits ground, adds to the footprint instead of reusing
  // what the mapping loop has freed. None of these threads is real-time
  // (roverd's loop is), and small blocks still come from per-thread caches
  // without the arena lock.
  ::mallopt(M_ARENA_MAX, 1);
  CLI::App app{
      "mapd: the rover's mapping process. Subscribes to roverd's estimates, stereo pairs and\n"
      "frame switches over iceoryx (RouDi must run: scripts/roudi.sh start, or the rover-roudi\n"
      "unit), starts a new submap when the filter's position sigma or the distance driven in\n"
      "the current one exceeds its limit, and asks roverd for the frame switch that gives it\n"
      "its origin. Maps the stereo pairs (SGBM depth, obstacle classification, 10 cm OctoMap\n"
      "and 5 cm cloud per submap) into OUT/mapd-<time>-<pid>.mcap. In threads below its own\n"
      "priority it matches finished submaps (4D: x, y, z, yaw) for loop closures and optimises\n"
      "the pose graph (frame switches, matches and AprilTag landmark sightings), logging every\n"
      "factor as it is added; the\n"
      "global map sits at the optimised origins. Stops on SIGTERM or SIGINT,\n"
      "then writes the global map beside the log (.bt, .ot for octovis; .ply) and prints its\n"
      "submaps.\n"};
  rover::mapd::MapdOptions options;
  std::string runtime_name = "mapd";
  double roudi_wait_s = 5.0;
  std::string config;
  app.add_option("--config", config,
                 "board profile (YAML, e.g. /etc/rover/board.yaml): its mapd and ipc sections set "
                 "the submap limits and the RouDi wait; options given here win");
  app.add_option("--runtime-name", runtime_name, "name registered with RouDi")
      ->capture_default_str();
  app.add_option("--submap-distance-m", options.trigger.max_distance_m,
                 "new submap after this distance driven in the current one")
      ->capture_default_str();
  app.add_option("--submap-sigma-m", options.trigger.max_position_sigma_m,
                 "new submap when the filter's position sigma exceeds this")
      ->capture_default_str();
  app.add_option("--roudi-wait-s", roudi_wait_s, "how long to wait for RouDi")
      ->capture_default_str();
  std::string out_dir;
  app.add_option("--out", out_dir,
                 "folder for mapd's log and the exported map (default: the board's log.folder; "
                 "none without --config)");
  bool no_mapping = false;
  app.add_flag("--no-mapping", no_mapping, "only follow the submaps, map nothing");
  app.add_option("--mapping-rate-hz", options.max_mapping_rate_hz,
                 "pairs mapped per second of capture time at most (0: all mapd keeps up with)")
      ->capture_default_str();
  app.add_option("--robot", options.robot_name, "robot name in frame ids (default: board.name)");
  bool no_loop_closures = false;
  app.add_flag("--no-loop-closures", no_loop_closures,
               "match no submaps: the pose graph holds only the filter's frame switches");
  std::string tags_file;
  app.add_option("--tags", tags_file,
                 "AprilTag marker file (YAML: families, sizes, which landmark or robot carries "
                 "each id; see mapping/README.md); detections of landmarks join the pose graph. "
                 "Default: the board's mapd.tags; none: no tag detection");
  app.add_option("--tag-tables", options.tag_tables_dir,
                 "folder of the tag error tables (rover-tags lut); default: the board's "
                 "mapd.tag_tables, else beside mapd's log");
  bool no_tags = false;
  app.add_flag("--no-tags", no_tags, "no AprilTag detection, whatever the board says");
  bool match_6d = false;
  app.add_flag("--match-6d", match_6d,
               "match submaps with the 6D baseline (6D RANSAC and ICP) instead of the 4D "
               "matcher that uses the submaps' gravity alignment");
  std::string team_file;
  app.add_option("--team", team_file,
                 "team file (YAML: DDS domain, each robot's id, name, address and radio "
                 "interface, the link's byte budget; see firmware/mapd/team_config.h): this "
                 "rover shares its graph's factors with the team over Cyclone DDS and adds theirs "
                 "to its own graph. Needs --robot-id");
  app.add_option("--robot-id", options.robot_id,
                 "this rover's id in the pose graph and in the team file")
      ->check(CLI::Range(0, 65535))
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  std::optional<rover::mapd::TeamConfig> team;
  if (!team_file.empty()) {
    try {
      const rover::ConfigNode root = rover::ConfigNode::LoadFile(team_file);
      team = rover::mapd::TeamConfig::Load(root, options.robot_id);
      root.CheckNoUnknownKeysRecursive();
      options.team = team->worker;
      if (app.get_option("--robot")->count() == 0) options.robot_name = team->Self().name;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "mapd: team file: %s\n", e.what());
      return 78;  // EX_CONFIG
    }
  }
  if (!config.empty()) {
    try {
      const auto board = rover::runtime::BoardConfig::LoadFile(config);
      if (app.get_option("--submap-distance-m")->count() == 0) {
        options.trigger.max_distance_m = board.mapd.submap_max_distance_m;
      }
      if (app.get_option("--submap-sigma-m")->count() == 0) {
        options.trigger.max_position_sigma_m = board.mapd.submap_max_position_sigma_m;
      }
      if (app.get_option("--roudi-wait-s")->count() == 0) roudi_wait_s = board.ipc.roudi_wait_s;
      if (app.get_option("--mapping-rate-hz")->count() == 0) {
        options.max_mapping_rate_hz = board.mapd.mapping_rate_hz;
      }
      if (!board.mapd.mapping) options.mapping = false;
      options.switch_noise.along_sigma_per_m = board.mapd.switch_along_sigma_per_m;
      options.switch_noise.across_sigma_per_m = board.mapd.switch_across_sigma_per_m;
      options.switch_noise.yaw_sigma_rad_per_m = board.mapd.switch_yaw_sigma_rad_per_m;
      if (out_dir.empty()) out_dir = board.log.folder;
      if (tags_file.empty()) tags_file = board.mapd.tags;
      if (options.tag_tables_dir.empty()) options.tag_tables_dir = board.mapd.tag_tables;
      options.build_missing_tag_tables = board.mapd.build_missing_tag_tables;
      if (app.get_option("--robot")->count() == 0 && !team) options.robot_name = board.board.name;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "mapd: %s\n", e.what());
      return 78;  // EX_CONFIG: systemd does not restart a bad configuration
    }
  }
  if (no_mapping) options.mapping = false;
  if (!tags_file.empty() && !no_tags && options.mapping) {
    try {
      const rover::ConfigNode root = rover::ConfigNode::LoadFile(tags_file);
      options.tags = rover::mapping::TagObserverOptions::Load(root);
      root.CheckNoUnknownKeysRecursive();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "mapd: tag markers: %s\n", e.what());
      return 78;  // EX_CONFIG
    }
  }
  if (no_loop_closures) options.loop_closures = false;
  if (match_6d) options.loop.matcher.mode = rover::mapping::MatchMode::kSixDof;
  if (!out_dir.empty() && options.mapping) {
    options.output_stem = (std::filesystem::path(out_dir) / LogStem()).string();
  }
  std::signal(SIGTERM, OnSignal);
  std::signal(SIGINT, OnSignal);
  try {
    std::string error;
    auto transport = rover::ipc::IceoryxTransport::Create(
        {.runtime_name = runtime_name,
         .roudi_wait_timeout = rover::Duration::FromSeconds(roudi_wait_s)},
        &error);
    if (transport == nullptr) {
      std::fprintf(stderr, "mapd: %s\n", error.c_str());
      return 2;
    }
    std::unique_ptr<rover::link::LinkEndpoint> team_link;
    if (team) {
      team_link = std::make_unique<rover::link::DdsLink>(
          rover::link::DdsLinkOptions{.self = static_cast<rover::link::RobotId>(team->self),
                                      .domain_id = team->domain_id,
                                      .config_xml = team->DdsConfigXml()});
      std::fprintf(stderr, "mapd: team: robot %d (%s) on %s, DDS domain %u, %zu peers\n",
                   team->self, team->Self().name.c_str(), team->Self().interface_name.c_str(),
                   team->domain_id, team->PeerAddresses().size());
    }
    rover::mapd::Mapd mapd(options, transport.get(), std::move(team_link));
    std::fprintf(stderr, "mapd: running (pid %d)\n", static_cast<int>(::getpid()));
    // Under systemd (Type=notify, WatchdogSec=): ready now, and alive as
    // long as this loop turns.
    const auto notifier = rover::runtime::SystemdNotifier::FromEnvironment();
    notifier.Ready();
    const auto ping = notifier.watchdog_ping_period();
    rover::Time next_ping = rover::Time::Now();
    while (g_stop == 0) {
      if (mapd.Poll() == 0) std::this_thread::sleep_for(std::chrono::milliseconds(2));
      if (ping && next_ping < rover::Time::Now()) {
        notifier.Watchdog();
        next_ping = rover::Time::Now() + *ping;
      }
    }
    notifier.Stopping();
    mapd.Shutdown();
    std::fprintf(stderr, "%s", mapd.Summary().c_str());
    if (!mapd.log_path().empty()) {
      std::fprintf(stderr, "mapd: log %s, global map %s.{bt,ot,ply}\n", mapd.log_path().c_str(),
                   options.output_stem.c_str());
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mapd: %s\n", e.what());
    return 2;
  }
}
