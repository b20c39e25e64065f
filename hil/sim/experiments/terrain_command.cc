#include "hil/sim/experiments/terrain_command.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <memory>
#include <stdexcept>

#include "firmware/mapd/local_mapper.h"
#include "hil/sim/experiments/map_command.h"
#include "hil/sim/motion/rover_trajectory.h"
#include "hil/sim/motion/trajectory_sample.h"
#include "hil/sim/render/stereo_camera.h"
#include "hil/sim/render/stereo_renderer.h"
#include "hil/sim/scenario/scenario.h"
#include "hil/sim/world/world.h"
#include "mapping/submap/submap.h"

namespace rover::sim::experiments {
namespace {

std::string Num(double v, int digits) {
  if (!std::isfinite(v)) return "nan";
  char text[48];
  std::snprintf(text, sizeof(text), "%.*f", digits, v);
  return text;
}

// Mean and the two ends of `values` ("mean 0.95 [0.91, 0.99]"), NaNs left out.
std::string Spread(const std::vector<double>& values) {
  double sum = 0.0;
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  int n = 0;
  for (const double v : values) {
    if (!std::isfinite(v)) continue;
    sum += v;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
    ++n;
  }
  if (n == 0) return "nan";
  return "mean " + Num(sum / n, 3) + " [" + Num(lo, 3) + ", " + Num(hi, 3) + "] over " +
         std::to_string(n);
}

}  // namespace

void TerrainCommandOptions::Validate() const {
  if (!(std::isfinite(rate_hz) && rate_hz > 0.0)) {
    throw std::invalid_argument("TerrainCommandOptions.rate_hz: expected > 0, found " +
                                std::to_string(rate_hz));
  }
  if (!(max_duration_s >= 0.0)) {
    throw std::invalid_argument("TerrainCommandOptions.max_duration_s: expected >= 0, found " +
                                std::to_string(max_duration_s));
  }
  if (seeds.empty()) {
    throw std::invalid_argument("TerrainCommandOptions.seeds: expected at least one seed");
  }
}

TerrainResult EvaluateTerrain(const TerrainCommandOptions& options, uint64_t seed) {
  options.Validate();
  const auto start = std::chrono::steady_clock::now();
  const Scenario scenario =
      LoadScenario(FindScenario(DefaultScenarioDir(), options.scenario), DefaultSimConfigDir());
  const World world = World::Generate(scenario.world, seed);
  const RoverTrajectory trajectory(scenario.route, world.terrain);
  ObstacleRuleOptions rule;
  rule.rock_min_height_m = rule.step_height_m;  // as `rover-sim map` scores missions
  const ObstacleGrid truth = ComputeObstacleCells(world, rule);

  const Eigen::Isometry3d& T_body_cam0 = scenario.camera.T_body_cam0;
  StereoRenderer renderer(world, scenario.camera);
  mapd::LocalMapper mapper({}, CameraModelOf(scenario.camera, T_body_cam0),
                           CameraModelOf(scenario.camera, scenario.camera.T_body_cam1()));
  // The world as the submap frame: it is gravity-aligned like mapd's.
  mapping::Submap submap(0, 0, {});
  const double end_s = options.max_duration_s > 0.0
                           ? std::min(options.max_duration_s, trajectory.duration_s())
                           : trajectory.duration_s();
  const double camera_rate_hz = scenario.camera.rate_hz;
  RenderedStereoFrame frame;
  TerrainResult result;
  result.seed = seed;
  for (double t_s = 0.0; t_s <= end_s; t_s += 1.0 / options.rate_hz) {
    const Eigen::Isometry3d T_world_body = PoseOf(trajectory.Evaluate(t_s));
    renderer.Render(T_world_body, {}, static_cast<uint64_t>(std::lround(t_s * camera_rate_hz)),
                    &frame);
    mapper.Process(frame.cam0, frame.cam1, T_world_body, &submap);
    ++result.pairs;
  }
  // The camera along the mapped stretch, every 0.25 s, as `rover-sim map`.
  const RectifiedHead head = RectifiedHeadOf(scenario.camera);
  std::vector<Eigen::Isometry3d> cameras;
  for (double t_s = 0.0; t_s <= end_s; t_s += 0.25) {
    cameras.push_back(PoseOf(trajectory.Evaluate(t_s)) * head.T_body_cam0rect);
  }
  result.quality = EvaluateMap(world, truth, rule, submap.octree(), submap.cloud(), cameras,
                               head.stereo, options.quality);
  result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

std::string TerrainResultFields(const TerrainResult& r) {
  const MapQuality& q = r.quality;
  return "seed=" + std::to_string(r.seed) + " pairs=" + std::to_string(r.pairs) +
         " obstacle_precision=" + Num(q.obstacle_precision, 4) +
         " obstacle_recall=" + Num(q.obstacle_recall, 4) +
         " obstacle_points=" + std::to_string(q.obstacle_points) +
         " obstacle_points_true=" + std::to_string(q.obstacle_points_true) +
         " truth_cells_observed=" + std::to_string(q.truth_obstacle_cells_observed) +
         " truth_cells_found=" + std::to_string(q.truth_obstacle_cells_found) +
         " map_precision=" + Num(q.map_precision, 4) + " map_recall=" + Num(q.map_recall, 4);
}

int RunTerrain(const TerrainCommandOptions& options, std::ostream& out, std::ostream& err) {
  try {
    options.Validate();
    std::vector<double> precision, recall;
    for (const uint64_t seed : options.seeds) {
      const TerrainResult r = EvaluateTerrain(options, seed);
      out << "RESULT scenario=" << options.scenario << " " << TerrainResultFields(r)
          << " wall_s=" << Num(r.wall_s, 1) << std::endl;
      precision.push_back(r.quality.obstacle_precision);
      recall.push_back(r.quality.obstacle_recall);
    }
    out << "obstacle precision " << Spread(precision) << "\nobstacle recall    " << Spread(recall)
        << "\n";
    return cli::kExitOk;
  } catch (const std::exception& e) {
    err << "rover-sim terrain: " << e.what() << "\n";
    return cli::kExitBadInput;
  }
}

cli::Subcommand AddTerrainCommand(CLI::App& app) {
  auto options = std::make_shared<TerrainCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "terrain",
      "mapd's obstacle classification on a scenario's rendered pairs at the true poses (no\n"
      "estimator, no IPC): SGBM depth, negative edges, error-adaptive steps, flags into the\n"
      "submap cloud, scored against the world's obstacle cells as `rover-sim map` scores a\n"
      "mission. One RESULT line per seed, then the spread.");
  cmd->add_option("--sim", options->scenario, "scenario")->capture_default_str();
  cmd->add_option("--seed", options->seeds, "world seed (repeatable)")->capture_default_str();
  cmd->add_option("--rate-hz", options->rate_hz, "pairs mapped per second of the route")
      ->capture_default_str();
  cmd->add_option("--max-duration-s", options->max_duration_s,
                  "map only the first S seconds of the route (0: all)")
      ->capture_default_str();
  AddObstacleScoringOptions(cmd, &options->quality);
  return {cmd, [options] { return RunTerrain(*options, std::cout, std::cerr); }};
}

}  // namespace rover::sim::experiments
