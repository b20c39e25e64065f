// mapd's per-image pipeline (firmware/mapd LocalMapper) on the simulator's
// rendered stereo pairs, scored against the world's ground truth: the depth
// points lie on the true terrain, and the obstacle flags sit on true
// obstacles. The single-image part of what `rover-sim map` measures on
// whole missions.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <vector>

#include "core/stats/percentile.h"
#include "firmware/mapd/local_mapper.h"
#include "hil/sim/mission/sim_mission.h"
#include "hil/sim/motion/rover_trajectory.h"
#include "hil/sim/render/stereo_renderer.h"
#include "hil/sim/scenario/scenario.h"
#include "hil/sim/world/world.h"

namespace rover::sim {
namespace {

bool IsObstacle(const ObstacleGrid& g, int ix, int iy) {
  if (ix < 0 || iy < 0 || ix >= g.cols || iy >= g.rows) return false;
  const ObstacleCode c = g.CodeAt(ix, iy);
  return c == ObstacleCode::kPositive || c == ObstacleCode::kNegative;
}

class MappingOnRenderTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scenario_ = new Scenario(
        LoadScenario(FindScenario(DefaultScenarioDir(), "short"), DefaultSimConfigDir()));
    world_ = new World(World::Generate(scenario_->world, 1));
    trajectory_ = new RoverTrajectory(scenario_->route, world_->terrain);
    ObstacleRuleOptions rule;
    rule.rock_min_height_m = rule.step_height_m;  // rocks taller than a wheel climbs
    truth_ = new ObstacleGrid(ComputeObstacleCells(*world_, rule));
    renderer_ = new StereoRenderer(*world_, scenario_->camera);
  }
  static void TearDownTestSuite() {
    delete renderer_;
    delete truth_;
    delete trajectory_;
    delete world_;
    delete scenario_;
  }

  MappingOnRenderTest()
      : mapper_(SingleImageOptions(),
                CameraModelOf(scenario_->camera, scenario_->camera.T_body_cam0),
                CameraModelOf(scenario_->camera, scenario_->camera.T_body_cam1())) {}

  Eigen::Isometry3d BodyAt(double t_s) const {
    const TrajectorySample s = trajectory_->Evaluate(t_s);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = s.q_world_body.toRotationMatrix();
    T.translation() = s.p_world_body;
    return T;
  }

  /// Each image on its own: no confirmation by a second one.
  static mapd::LocalMapperOptions SingleImageOptions() {
    mapd::LocalMapperOptions options;
    options.min_obstacle_images = 1;
    return options;
  }

  /// Renders and maps the pair at `t_s` (the world as the local frame).
  void MapAt(double t_s) {
    RenderedStereoFrame frame;
    T_world_body_ = BodyAt(t_s);
    renderer_->Render(T_world_body_, {}, static_cast<uint64_t>(t_s * 10), &frame);
    mapping::Submap submap(0, 0, {});
    mapper_.Process(frame.cam0, frame.cam1, T_world_body_, &submap);
  }

  /// Calls fn(world point, obstacle flag) for every valid depth point.
  template <typename Fn>
  void ForEachPoint(Fn&& fn) const {
    const mapping::DepthImage& depth = *mapper_.last_depth();
    const Eigen::Isometry3d T_world_cam = T_world_body_ * mapper_.T_body_cam();
    const std::vector<uint8_t>& mask = mapper_.last_obstacle_mask();
    for (int v = 0; v < depth.height(); ++v) {
      for (int u = 0; u < depth.width(); ++u) {
        if (depth.state(u, v) != mapping::DepthState::kValid) continue;
        fn(T_world_cam * depth.point(u, v).cast<double>(),
           mask[static_cast<std::size_t>(v * depth.width() + u)] != 0);
      }
    }
  }

  static Scenario* scenario_;
  static World* world_;
  static RoverTrajectory* trajectory_;
  static ObstacleGrid* truth_;
  static StereoRenderer* renderer_;
  mapd::LocalMapper mapper_;
  Eigen::Isometry3d T_world_body_ = Eigen::Isometry3d::Identity();
};

Scenario* MappingOnRenderTest::scenario_ = nullptr;
World* MappingOnRenderTest::world_ = nullptr;
RoverTrajectory* MappingOnRenderTest::trajectory_ = nullptr;
ObstacleGrid* MappingOnRenderTest::truth_ = nullptr;
StereoRenderer* MappingOnRenderTest::renderer_ = nullptr;

TEST_F(MappingOnRenderTest, DepthPointsLieOnTheTrueTerrain) {
  std::vector<double> errors;
  std::vector<double> signed_errors;
  for (double t_s : {5.0, 15.0, 25.0}) {
    MapAt(t_s);
    ForEachPoint([&](const Eigen::Vector3d& p, bool) {
      const double e = p.z() - world_->terrain.HeightAt(p.x(), p.y());
      errors.push_back(std::abs(e));
      signed_errors.push_back(e);
    });
  }
  ASSERT_GT(errors.size(), 100000u);
  // Depth too long along rays that look down puts the ground below the
  // terrain: SGBM's top-down aggregation did that by 0.3-0.7 % of depth.
  const double median_signed_m = stats::Percentile(signed_errors, 50.0);
  std::printf("height error median (signed) %.4f m\n", median_signed_m);
  std::sort(errors.begin(), errors.end());
  const double within =
      static_cast<double>(std::lower_bound(errors.begin(), errors.end(), 0.1) - errors.begin()) /
      static_cast<double>(errors.size());
  std::printf("height error |e|: p50 %.3f m, p90 %.3f m, max %.3f m; within 0.1 m: %.4f\n",
              errors[errors.size() / 2], errors[errors.size() * 9 / 10], errors.back(), within);
  // The sky and the image border give no points (texture filter, border
  // margin): nothing floats.
  EXPECT_GT(within, 0.995);
  EXPECT_LT(errors[errors.size() * 9 / 10], 0.03);
  EXPECT_LT(std::abs(median_signed_m), 0.002);
}

TEST_F(MappingOnRenderTest, ObstacleFlagsSitOnTrueObstaclesAndFindThem) {
  // The pairs with the most true obstacle cells in view within stereo range
  // (the route itself steers clear of them).
  std::vector<std::pair<int, double>> candidates;
  for (double t_s = 2.0; t_s < trajectory_->duration_s(); t_s += 1.0) {
    const Eigen::Isometry3d T = BodyAt(t_s);
    int cells = 0;
    for (double ahead = 1.0; ahead <= 3.5; ahead += truth_->resolution_m) {
      for (double side = -2.5; side <= 2.5; side += truth_->resolution_m) {
        const Eigen::Vector3d p = T * Eigen::Vector3d(ahead, side, 0.0);
        const int ix = static_cast<int>((p.x() - truth_->origin_xy.x()) / truth_->resolution_m);
        const int iy = static_cast<int>((p.y() - truth_->origin_xy.y()) / truth_->resolution_m);
        if (IsObstacle(*truth_, ix, iy)) ++cells;
      }
    }
    candidates.push_back({cells, t_s});
  }
  std::sort(candidates.rbegin(), candidates.rend());
  ASSERT_GT(candidates.front().first, 10) << "the short route passes no obstacle";
  int flagged = 0;
  int flagged_true = 0;
  int truth_seen = 0;
  int truth_found = 0;
  for (int k = 0; k < 3; ++k) {
    MapAt(candidates[static_cast<std::size_t>(k)].second);
    const double res = truth_->resolution_m;
    std::vector<uint8_t> seen(static_cast<std::size_t>(truth_->cols * truth_->rows), 0);
    std::vector<uint8_t> hit(seen.size(), 0);
    ForEachPoint([&](const Eigen::Vector3d& p, bool obstacle) {
      const int ix = static_cast<int>((p.x() - truth_->origin_xy.x()) / res);
      const int iy = static_cast<int>((p.y() - truth_->origin_xy.y()) / res);
      const auto cell = static_cast<std::size_t>(iy * truth_->cols + ix);
      seen[cell] = 1;
      if (!obstacle) return;
      hit[cell] = 1;
      ++flagged;
      bool near = false;
      for (int dy = -3; dy <= 3 && !near; ++dy) {
        for (int dx = -3; dx <= 3 && !near; ++dx) near = IsObstacle(*truth_, ix + dx, iy + dy);
      }
      if (near) ++flagged_true;
    });
    for (int iy = 3; iy < truth_->rows - 3; ++iy) {
      for (int ix = 3; ix < truth_->cols - 3; ++ix) {
        if (!seen[static_cast<std::size_t>(iy * truth_->cols + ix)] || !IsObstacle(*truth_, ix, iy))
          continue;
        ++truth_seen;
        bool found = false;
        for (int dy = -3; dy <= 3 && !found; ++dy) {
          for (int dx = -3; dx <= 3 && !found; ++dx) {
            found = hit[static_cast<std::size_t>((iy + dy) * truth_->cols + ix + dx)] != 0;
          }
        }
        if (found) ++truth_found;
      }
    }
  }
  std::printf(
      "obstacles: %d flagged points, %d near true obstacles; %d true obstacle cells seen, "
      "%d found\n",
      flagged, flagged_true, truth_seen, truth_found);
  ASSERT_GT(truth_seen, 100);
  EXPECT_GT(static_cast<double>(flagged_true) / flagged, 0.95);
  // One image sees these rocks only at 3.3-4.4 m, at the far end of stereo
  // range, where the error-adaptive threshold is high and the ground around
  // them sparse (measured: 0.91, rock tops filled whole); the mission's map
  // sees them again closer (rover-sim map scores that).
  EXPECT_GT(static_cast<double>(truth_found) / truth_seen, 0.75);
}

}  // namespace
}  // namespace rover::sim
