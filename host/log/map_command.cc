#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>

#include "host/log/commands.h"
#include "host/log/format.h"
#include "host/log/submap_chain.h"
#include "mapping/compose/map_composer.h"
#include "mapping/compose/map_export.h"
#include "mapping/compose/submap_log.h"
#include "mapping/slam/graph_log.h"
#include "mapping/slam/team_graph.h"

namespace rover::host {
namespace {

using Clock = std::chrono::steady_clock;

double MillisecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// Occupied finest voxels: a pruned occupied leaf counts for every voxel it
// covers.
uint64_t OccupiedVoxels(const octomap::OcTree& tree) {
  const unsigned max_depth = tree.getTreeDepth();
  uint64_t voxels = 0;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    if (tree.isNodeOccupied(*it)) voxels += uint64_t{1} << (3 * (max_depth - it.getDepth()));
  }
  return voxels;
}

void PrintSubmapTable(const mapping::SubmapLog& log, const std::vector<bool>& placed,
                      std::ostream& out) {
  char line[256];
  std::snprintf(line, sizeof line, "    %6s %6s %7s %11s %12s %12s  %s\n", "index", "frame",
                "images", "distance_m", "octree", "cloud", "placed");
  out << line;
  for (std::size_t i = 0; i < log.submaps.size(); ++i) {
    const log::rover_msgs::SubmapInfo& info = log.submaps[i].info;
    std::snprintf(line, sizeof line, "    %6u %6u %7u %11.2f %12s %12s  %s\n", info.index,
                  info.frame_id, info.images, info.distance_m,
                  FormatBytes(info.octree_bytes).c_str(), FormatBytes(info.cloud_bytes).c_str(),
                  placed[i] ? "yes" : "no");
    out << line;
  }
}

// Composes the placed submaps (in log then submap order, the order mapd
// built them), prints the map's figures and writes the files.
int ComposeAndWrite(const MapOptions& options, const std::vector<mapping::SubmapLog>& logs,
                    const mapping::SubmapPlacements& placement, std::size_t total_submaps,
                    std::size_t problem_count, std::size_t unplaced_count, std::ostream& out,
                    std::ostream& err) {
  const char* const kTool = "rover-log map: ";
  const double resolution_m = placement.resolution_m;
  const std::vector<mapping::SubmapPlacement>& placements = placement.placed;
  mapping::MapComposerOptions composer_options;
  composer_options.resolution_m = resolution_m;
  std::optional<mapping::MapComposer> composer;
  const octomap::OcTree* tree = nullptr;
  const bool show_progress = placements.size() >= options.progress_min_submaps;
  const std::size_t progress_step = std::max<std::size_t>(1, placements.size() / 10);
  const Clock::time_point compose_start = Clock::now();
  try {
    composer.emplace(composer_options);
    for (std::size_t i = 0; i < placements.size(); ++i) {
      const mapping::SubmapPlacement& p = placements[i];
      const mapping::LoggedSubmap& s = logs[p.log].submaps[p.submap];
      composer->SetSubmap(static_cast<uint32_t>(i), s.octree, s.cloud, p.T_map_submap);
      if (show_progress && ((i + 1) % progress_step == 0 || i + 1 == placements.size())) {
        // Merging now costs no more than merging all at the end: each call
        // appends only the new submaps to the cached composition.
        composer->Compose();
        err << kTool << "composing: " << i + 1 << "/" << placements.size() << " submaps\n";
      }
    }
    tree = &composer->Compose();
  } catch (const std::exception& e) {
    err << kTool << "composing the map failed: " << e.what() << "\n";
    return 2;
  }
  const double octree_ms = MillisecondsSince(compose_start);
  mapping::PointCloud cloud;
  double cloud_ms = 0.0;
  if (options.compose_cloud) {
    const Clock::time_point cloud_start = Clock::now();
    cloud = composer->ComposedCloud();
    cloud_ms = MillisecondsSince(cloud_start);
  }
  const mapping::MapComposerStats stats = composer->Stats();
  std::size_t obstacles = 0;
  for (const mapping::CloudPoint& p : cloud) obstacles += p.obstacle ? 1 : 0;

  char line[256];
  out << "composed map:\n";
  out << "  submaps placed:   " << placements.size() << " of " << total_submaps << "\n";
  std::snprintf(line, sizeof line, "  octree leaves:    %zu (resolution %.3f m)\n",
                stats.composed_leaves, resolution_m);
  out << line;
  out << "  occupied voxels:  " << OccupiedVoxels(*tree) << "\n";
  if (options.compose_cloud) {
    out << "  cloud points:     " << cloud.size() << "\n";
    out << "  obstacle points:  " << obstacles << "\n";
  } else {
    out << "  cloud points:     not composed (--no-cloud)\n";
  }
  out << "  memory:           octree " << FormatBytes(stats.octree_memory_bytes) << ", cloud "
      << FormatBytes(stats.cloud_memory_bytes) << "\n";
  std::snprintf(line, sizeof line, "  compose time:     octree %.1f ms, cloud %.1f ms\n", octree_ms,
                cloud_ms);
  out << line;

  // Write.
  std::vector<std::string> written;
  try {
    const std::filesystem::path parent = std::filesystem::path(options.out_stem).parent_path();
    if (!parent.empty()) std::filesystem::create_directories(parent);
    if (options.write_bt) {
      written.push_back(options.out_stem + ".bt");
      mapping::WriteOctreeBt(*tree, written.back());
    }
    if (options.write_ot) {
      written.push_back(options.out_stem + ".ot");
      mapping::WriteOctreeOt(*tree, written.back());
    }
    if (options.write_ply) {
      written.push_back(options.out_stem + ".ply");
      mapping::WritePly(cloud, written.back());
    }
  } catch (const std::exception& e) {
    err << kTool << "cannot write " << (written.empty() ? options.out_stem : written.back()) << ": "
        << e.what() << "\n";
    return 2;
  }
  out << "wrote:\n";
  for (const std::string& path : written) out << "  " << path << "\n";
  out << "view with: ";
  if (options.write_bt || options.write_ot) {
    out << "octovis " << (options.write_bt ? written.front() : options.out_stem + ".ot");
  }
  if (options.write_ply) {
    out << ((options.write_bt || options.write_ot) ? "; " : "") << written.back()
        << " in any PLY viewer (MeshLab, CloudCompare)";
  }
  out << "\n";

  if (problem_count > 0 || unplaced_count > 0) {
    err << kTool << "the map is incomplete: " << problem_count << " problem(s) in the input, "
        << unplaced_count << " submap(s) left out\n";
    return 1;
  }
  return 0;
}

// The team's map: each log's submaps at its rover's origins in the team's
// graph (SolveTeamGraph: the lowest robot's prior frames the map).
int RunTeamMap(const MapOptions& options, const std::vector<mapping::SubmapLog>& logs,
               const mapping::GraphLogContents& graphs, std::size_t total_submaps,
               std::ostream& out, std::ostream& err) {
  const char* const kTool = "rover-log map: ";
  const std::map<std::string, int>& robot_of_log = graphs.robot_of_log;
  mapping::TeamGraphSolution graph;
  try {
    graph = mapping::SolveTeamGraph(graphs);
  } catch (const std::exception& e) {
    err << kTool << "the team's graph: " << e.what() << "\n";
    return 2;
  }
  if (!options.roverd_log.empty()) {
    err << kTool << "--roverd-log is not used for a team's map: the team graph places it\n";
  }
  mapping::SubmapPlacements placement;
  std::vector<std::string> unplaced;
  std::size_t problem_count = graph.problems.size();
  out << "rover-log map: the team's map from " << logs.size() << " mapd logs of "
      << graph.robots.size() << " rovers, " << total_submaps << " submap(s); map frame: robot "
      << graph.anchor_robot << "'s first origin; team graph: " << graph.factors << " factors ("
      << graph.priors_left_out << " other rovers' priors left out)\n";
  for (std::size_t l = 0; l < logs.size(); ++l) {
    const auto robot = robot_of_log.find(options.mapd_logs[l]);
    std::map<uint32_t, Eigen::Isometry3d> origins;
    if (robot != robot_of_log.end()) {
      for (const auto& [key, T] : graph.origins) {
        if (key.first == robot->second) origins[static_cast<uint32_t>(key.second)] = T;
      }
    }
    const mapping::SubmapPlacements one = mapping::PlaceLoggedSubmaps({logs[l]}, origins);
    if (placement.placed.empty() && !one.placed.empty()) placement.resolution_m = one.resolution_m;
    for (mapping::SubmapPlacement p : one.placed) {
      p.log = l;
      placement.placed.push_back(p);
    }
    out << "log " << l + 1 << ": " << options.mapd_logs[l] << " (robot "
        << (robot == robot_of_log.end() ? std::string("unknown: no origins logged")
                                        : std::to_string(robot->second))
        << "): " << one.placed.size() << " of " << logs[l].submaps.size() << " submaps placed\n";
    for (const mapping::UnplacedSubmap& u : one.unplaced) {
      unplaced.push_back("log " + std::to_string(l + 1) + " submap " +
                         std::to_string(logs[l].submaps[u.submap].info.index) +
                         ": its frame is not linked to robot " +
                         std::to_string(graph.anchor_robot) + "'s map");
    }
    problem_count += logs[l].problems.size();
    for (const std::string& p : logs[l].problems) out << "    " << p << "\n";
  }
  for (const std::string& p : graph.problems) out << "  team graph: " << p << "\n";
  out << "unplaced submaps: " << unplaced.size() << "\n";
  for (const std::string& u : unplaced) out << "  " << u << "\n";
  if (placement.placed.empty()) {
    err << kTool << "none of the " << total_submaps << " submap(s) could be placed\n";
    return 2;
  }
  return ComposeAndWrite(options, logs, placement, total_submaps, problem_count, unplaced.size(),
                         out, err);
}

}  // namespace

int RunMap(const MapOptions& options, std::ostream& out, std::ostream& err) {
  const char* const kTool = "rover-log map: ";
  // Usage.
  if (options.mapd_logs.empty()) {
    err << kTool << "no mapd log given\n";
    return 2;
  }
  // Several rovers' logs: the team's map, at the team graph's origins.
  mapping::GraphLogContents graphs;
  try {
    graphs = mapping::ReadGraphLogs(options.mapd_logs);
  } catch (const std::exception&) {
    // An unreadable log is reported when the submaps are read below.
  }
  std::set<int> robots;
  for (const auto& [path, robot] : graphs.robot_of_log) robots.insert(robot);
  const bool team = robots.size() > 1;
  if (!team && options.roverd_log.empty() && options.mapd_logs.size() > 1) {
    err << kTool << options.mapd_logs.size()
        << " mapd logs need --roverd-log ROVERD.mcap: only roverd's frame switches place the "
           "submaps of a restarted mapd in one frame\n";
    return 2;
  }
  if (options.out_stem.empty()) {
    err << kTool << "no output given (--out STEM)\n";
    return 2;
  }
  if (!options.write_bt && !options.write_ot && !options.write_ply) {
    err << kTool << "no output format selected (--format bt,ot,ply)\n";
    return 2;
  }
  if (options.write_ply && !options.compose_cloud) {
    err << kTool << "--no-cloud leaves nothing for the .ply; select --format bt,ot\n";
    return 2;
  }

  // Read every mapd log; damage inside one is a problem, not an error.
  std::vector<mapping::SubmapLog> logs;
  std::size_t total_submaps = 0;
  for (std::size_t i = 0; i < options.mapd_logs.size(); ++i) {
    const std::string& path = options.mapd_logs[i];
    if (options.mapd_logs.size() > 1) {
      err << kTool << "reading " << path << " (" << i + 1 << "/" << options.mapd_logs.size()
          << ")\n";
    }
    try {
      logs.push_back(mapping::ReadSubmapLog(path));
    } catch (const std::exception& e) {
      err << kTool << e.what() << "\n";
      return 2;
    }
    total_submaps += logs.back().submaps.size();
  }
  if (total_submaps == 0) {
    err << kTool << "no submaps in";
    for (const std::string& path : options.mapd_logs) err << " " << path;
    err << " (no complete " << mapping::kSubmapInfoTopic << " + " << mapping::kSubmapOctomapTopic
        << " + " << mapping::kSubmapCloudTopic << " message triple; is this a mapd log?)\n";
    for (const mapping::SubmapLog& l : logs) {
      for (const std::string& p : l.problems) err << "  " << p << "\n";
    }
    return 2;
  }

  if (team) {
    return RunTeamMap(options, logs, graphs, total_submaps, out, err);
  }
  // Where each frame lies in the map frame.
  std::map<uint32_t, Eigen::Isometry3d> origins;
  if (!options.roverd_log.empty()) {
    try {
      origins = mapping::ReadFrameOrigins(options.roverd_log);
    } catch (const std::exception& e) {
      err << kTool << e.what() << "\n";
      return 2;
    }
  } else {
    origins = ChainSubmapOrigins(logs.front().submaps);
  }
  // The pose graph's optimised origins, as mapd composed its map: the last
  // update of the newest log that has one (a restarted mapd carries the
  // whole graph on).
  std::size_t graph_placed = 0;
  if (options.use_graph) {
    for (auto path = options.mapd_logs.rbegin(); path != options.mapd_logs.rend(); ++path) {
      const mapping::GraphLogContents graph = mapping::ReadGraphLogs({*path});
      if (!graph.last_origins) continue;
      graph_placed = mapping::PlaceAtGraphOrigins(*graph.last_origins, &origins);
      break;
    }
  }

  // The submaps that can be placed (mapping/compose's one placement rule).
  const mapping::SubmapPlacements placement = mapping::PlaceLoggedSubmaps(logs, origins);
  const double resolution_m = placement.resolution_m;
  const std::vector<mapping::SubmapPlacement>& placements = placement.placed;
  std::vector<std::vector<bool>> placed(logs.size());
  for (std::size_t l = 0; l < logs.size(); ++l) placed[l].assign(logs[l].submaps.size(), false);
  for (const mapping::SubmapPlacement& p : placements) placed[p.log][p.submap] = true;
  std::vector<std::string> unplaced;
  for (const mapping::UnplacedSubmap& u : placement.unplaced) {
    const log::rover_msgs::SubmapInfo& info = logs[u.log].submaps[u.submap].info;
    const std::string name = "log " + std::to_string(u.log + 1) + " submap " +
                             std::to_string(info.index) + " (frame " +
                             std::to_string(info.frame_id) + ")";
    if (u.reason == mapping::UnplacedSubmap::Reason::kResolution) {
      char why[128];
      std::snprintf(why, sizeof why, ": octree resolution %.3f m, the map's is %.3f m",
                    u.resolution_m, resolution_m);
      unplaced.push_back(name + why);
    } else {
      unplaced.push_back(name + ": " +
                         (options.roverd_log.empty()
                              ? WhyUnplaced(info, origins)
                              : "no frame switch of " + options.roverd_log + " reaches frame " +
                                    std::to_string(info.frame_id)));
    }
  }

  // Per log: its submaps and problems.
  std::size_t problem_count = 0;
  out << "rover-log map: " << logs.size() << " mapd log(s), " << total_submaps
      << " submap(s); map frame: "
      << (options.roverd_log.empty() ? "the first submap's frame (chained by SubmapInfo origins)"
                                     : "frame 0 of " + options.roverd_log + " (" +
                                           std::to_string(origins.size()) + " frame(s) placed)")
      << "; " << graph_placed << " frame(s) at the pose graph's optimised origins\n";
  for (std::size_t l = 0; l < logs.size(); ++l) {
    const mapping::SubmapLog& log = logs[l];
    out << "log " << l + 1 << ": " << options.mapd_logs[l] << "\n";
    out << "  submaps: " << log.submaps.size()
        << ", traversability grids: " << log.traversability_grids << ", mapd statistics: "
        << (log.statistics.empty() ? "absent (mapd did not stop cleanly)" : "present") << "\n";
    if (!log.submaps.empty()) PrintSubmapTable(log, placed[l], out);
    if (!log.problems.empty()) {
      out << "  problems: " << log.problems.size() << "\n";
      for (const std::string& p : log.problems) out << "    " << p << "\n";
    }
    problem_count += log.problems.size();
  }
  out << "unplaced submaps: " << unplaced.size() << "\n";
  for (const std::string& u : unplaced) out << "  " << u << "\n";
  if (placements.empty()) {
    err << kTool << "none of the " << total_submaps << " submap(s) could be placed\n";
    return 2;
  }

  return ComposeAndWrite(options, logs, placement, total_submaps, problem_count, unplaced.size(),
                         out, err);
}

}  // namespace rover::host
