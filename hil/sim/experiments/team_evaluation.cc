#include "hil/sim/experiments/team_evaluation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>

#include "hil/sim/experiments/map_command.h"
#include "mapping/compose/submap_log.h"
#include "mapping/slam/graph_log.h"

namespace rover::sim::experiments {
namespace {

namespace fs = std::filesystem;

// The logs in `folder` whose name starts with `prefix`, sorted.
std::vector<std::string> Logs(const std::string& folder, const std::string& prefix) {
  std::vector<std::string> out;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(folder, error)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) == 0 && entry.path().extension() == ".mcap") {
      out.push_back(entry.path().string());
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

double Number(const std::string& text) {
  if (text.empty()) return std::nan("");
  try {
    return std::stod(text);
  } catch (const std::exception&) {
    return std::nan("");
  }
}

std::string Fixed(double v, int digits) {
  if (!std::isfinite(v)) return "nan";
  char text[48];
  std::snprintf(text, sizeof(text), "%.*f", digits, v);
  return text;
}

// The largest finite value (nan if none).
double MaxFinite(double a, double b) {
  if (!std::isfinite(a)) return b;
  if (!std::isfinite(b)) return a;
  return std::max(a, b);
}

}  // namespace

std::string ResultLineField(const std::string& line, const std::string& key) {
  const std::size_t at = line.find(" " + key + "=");
  if (at == std::string::npos) return "";
  const std::size_t begin = at + key.size() + 2;
  return line.substr(begin, line.find_first_of(" \n", begin) - begin);
}

TeamResult EvaluateTeam(const std::string& scenario, const std::vector<TeamRoverRun>& runs,
                        std::ostream& report) {
  TeamResult r;
  std::vector<std::string> all_logs;
  for (const TeamRoverRun& run : runs) {
    const std::vector<std::string> logs = Logs(run.folder, "mapd-");
    all_logs.insert(all_logs.end(), logs.begin(), logs.end());
    double link_bytes_per_s = std::nan("");
    std::string received = "0";
    for (const std::string& path : logs) {
      const mapping::SubmapLog log = mapping::ReadSubmapLog(path);
      if (log.statistics.count("team_link_bytes_per_s")) {
        link_bytes_per_s = Number(log.statistics.at("team_link_bytes_per_s"));
        received = log.statistics.at("team_constraints_received");
      }
    }
    report << "  " << run.name << " (robot " << run.robot << "): " << logs.size()
           << " mapd log(s), " << received << " constraints received, link "
           << Fixed(link_bytes_per_s, 0) << " B/s\n";
    const std::string base = run.result_line.empty()
                                 ? "RESULT scenario=" + scenario + " slam_final_err_pct=nan"
                                 : run.result_line;
    r.rover_lines.push_back(base + " robot=" + std::to_string(run.robot) + " name=" + run.name +
                            " link_bytes_per_s=" + Fixed(link_bytes_per_s, 0) +
                            " team_constraints_received=" + received);
    r.link_bytes_per_s_max = MaxFinite(r.link_bytes_per_s_max, link_bytes_per_s);
    r.slam_final_err_pct_max =
        MaxFinite(r.slam_final_err_pct_max, Number(ResultLineField(base, "slam_final_err_pct")));
  }
  // Every factor once (each rover's log holds its own and what it received).
  const mapping::GraphLogContents graph = mapping::ReadGraphLogs(all_logs);
  std::map<int64_t, std::set<int>> landmark_robots;
  for (const mapping::GraphFactorRecord& f : graph.factors) {
    if (f.kind == mapping::FactorKind::kLandmarkObservation && f.b) {
      landmark_robots[f.b->index].insert(f.a.robot);
    }
  }
  for (const mapping::GraphFactorRecord& f : graph.factors) {
    if (f.kind == mapping::FactorKind::kSubmapMatch && f.b && f.b->robot != f.a.robot) {
      ++r.inter_robot_matches;
    } else if (f.kind == mapping::FactorKind::kRobotDetection) {
      ++r.robot_detections;
    } else if (f.kind == mapping::FactorKind::kLandmarkObservation && f.b &&
               landmark_robots[f.b->index].size() > 1) {
      ++r.shared_landmark_sightings;
    }
  }
  r.inter_robot_closures = r.inter_robot_matches + r.robot_detections + r.shared_landmark_sightings;
  report << "  team graph: " << graph.factors.size() << " factors from " << all_logs.size()
         << " logs; inter-robot: " << r.inter_robot_matches << " submap matches, "
         << r.robot_detections << " robot detections, " << r.shared_landmark_sightings
         << " sightings of shared landmarks\n";
  for (const std::string& p : graph.problems) report << "    problem: " << p << "\n";
  std::vector<TeamMapRover> map_rovers;
  for (const TeamRoverRun& run : runs) {
    const std::vector<std::string> missions = Logs(run.folder, "mission-");
    if (missions.size() != 1) continue;
    map_rovers.push_back({missions.front(), Logs(run.folder, "mapd-")});
  }
  try {
    if (map_rovers.size() != runs.size()) throw std::runtime_error("a rover has no flight log");
    const TeamMapResult map = EvaluateTeamMap(map_rovers, report);
    r.team_map_precision = map.quality.map_precision;
    r.team_map_recall = map.quality.map_recall;
    r.team_submaps_placed = map.submaps_placed;
    r.team_submaps = map.submaps;
  } catch (const std::exception& e) {
    report << "  team map: " << e.what() << "\n";
  }
  r.team_line = "RESULT team scenario=" + scenario + " rovers=" + std::to_string(runs.size()) +
                " inter_robot_closures=" + std::to_string(r.inter_robot_closures) +
                " inter_robot_matches=" + std::to_string(r.inter_robot_matches) +
                " robot_detections=" + std::to_string(r.robot_detections) +
                " shared_landmark_sightings=" + std::to_string(r.shared_landmark_sightings) +
                " slam_final_err_pct_max=" + Fixed(r.slam_final_err_pct_max, 4) +
                " link_bytes_per_s_max=" + Fixed(r.link_bytes_per_s_max, 0) +
                " team_map_precision=" + Fixed(r.team_map_precision, 4) +
                " team_map_recall=" + Fixed(r.team_map_recall, 4) +
                " team_submaps_placed=" + std::to_string(r.team_submaps_placed) + "/" +
                std::to_string(r.team_submaps);
  return r;
}

}  // namespace rover::sim::experiments
