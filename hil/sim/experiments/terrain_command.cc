#include "hil/sim/experiments/terrain_command.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>

#include "core/stats/percentile.h"
#include "firmware/mapd/local_mapper.h"
#include "hil/sim/experiments/map_command.h"
#include "hil/sim/motion/rover_trajectory.h"
#include "hil/sim/motion/trajectory_sample.h"
#include "hil/sim/render/stereo_camera.h"
#include "hil/sim/render/stereo_renderer.h"
#include "hil/sim/scenario/scenario.h"
#include "hil/sim/world/world.h"
#include "mapping/depth/depth_image.h"
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

// Signed depth errors of one depth image against the rendered z-depth of
// the distorted cam0 image: each measured point is projected into cam0 and
// its true point taken on the same ray (cam0 and cam0rect share the centre).
class DepthBiasAccumulator {
 public:
  DepthBiasAccumulator(const calib::CameraModel& cam0, const Eigen::Isometry3d& T_body_cam0,
                       const RectifiedHead& head)
      : cam0_(cam0),
        T_cam0_cam0rect_(T_body_cam0.inverse() * head.T_body_cam0rect),
        fb_px_m_(head.stereo.focal_px * head.stereo.baseline_m) {}

  void Add(const mapping::DepthImage& depth, const cv::Mat& depth0_m) {
    constexpr int kStride = 4;
    for (int v = 0; v < depth.height(); v += kStride) {
      for (int u = 0; u < depth.width(); u += kStride) {
        if (depth.state(u, v) != mapping::DepthState::kValid) continue;
        const Eigen::Vector3d p_rect = depth.point(u, v).cast<double>();
        const Eigen::Vector3d p_cam0 = T_cam0_cam0rect_ * p_rect;
        const std::optional<Eigen::Vector2d> px = cam0_.Project(p_cam0);
        if (!px || p_cam0.z() <= 0.0) continue;
        const int col = static_cast<int>(std::lround(px->x()));
        const int row = static_cast<int>(std::lround(px->y()));
        if (col < 0 || row < 0 || col >= depth0_m.cols || row >= depth0_m.rows) continue;
        const double z_true_cam0 = depth0_m.at<float>(row, col);
        if (!(z_true_cam0 > 0.0)) continue;
        const double z_true = p_rect.z() * z_true_cam0 / p_cam0.z();
        disparity_error_px_.push_back(fb_px_m_ / p_rect.z() - fb_px_m_ / z_true);
        const double relative = p_rect.z() / z_true - 1.0;
        if (z_true >= 1.0 && z_true < 3.0) near_.push_back(relative);
        if (z_true >= 3.0 && z_true < 5.0) mid_.push_back(relative);
      }
    }
  }

  DepthBias Result() const {
    DepthBias b;
    b.disparity_error_px_p50 = stats::Percentile(disparity_error_px_, 50.0);
    b.depth_error_1_3_m = stats::Percentile(near_, 50.0);
    b.depth_error_3_5_m = stats::Percentile(mid_, 50.0);
    return b;
  }

 private:
  calib::CameraModel cam0_;
  Eigen::Isometry3d T_cam0_cam0rect_;
  double fb_px_m_;
  std::vector<double> disparity_error_px_, near_, mid_;
};

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
  const calib::CameraModel cam0 = CameraModelOf(scenario.camera, T_body_cam0);
  mapd::LocalMapperOptions mapper_options;
  if (!options.disparity_mode.empty()) mapper_options.disparity.mode = options.disparity_mode;
  mapd::LocalMapper mapper(mapper_options, cam0,
                           CameraModelOf(scenario.camera, scenario.camera.T_body_cam1()));
  const RectifiedHead head = RectifiedHeadOf(scenario.camera);
  DepthBiasAccumulator depth_bias(cam0, T_body_cam0, head);
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
    if (const mapping::DepthImage* depth = mapper.last_depth()) {
      depth_bias.Add(*depth, frame.depth0_m);
    }
    ++result.pairs;
  }
  result.depth = depth_bias.Result();
  // The camera along the mapped stretch, every 0.25 s, as `rover-sim map`.
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
         " map_precision=" + Num(q.map_precision, 4) + " map_recall=" + Num(q.map_recall, 4) +
         " disparity_error_px_p50=" + Num(r.depth.disparity_error_px_p50, 3) +
         " depth_error_pct_1_3m=" + Num(100.0 * r.depth.depth_error_1_3_m, 2) +
         " depth_error_pct_3_5m=" + Num(100.0 * r.depth.depth_error_3_5_m, 2);
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
  cmd->add_option("--disparity-mode", options->disparity_mode,
                  "SGBM's path mode instead of mapd's: sgbm, sgbm_3way, hh4 or hh");
  AddObstacleScoringOptions(cmd, &options->quality);
  return {cmd, [options] { return RunTerrain(*options, std::cout, std::cerr); }};
}

}  // namespace rover::sim::experiments
