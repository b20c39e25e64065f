#include "hil/sim/experiments/map_evaluation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include <Eigen/Eigenvalues>

#include "core/calib/stereo_rectifier.h"
#include "mapping/depth/stereo_error_model.h"

namespace rover::sim::experiments {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Packs signed 2D cell indices into one hash key.
int64_t CellKey(int64_t ix, int64_t iy) { return (ix << 32) ^ (iy & 0xffffffff); }

struct Disc {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double radius_m = 0.0;
};

// Horizontal discs around the static tag carriers: rendered objects that
// the heightfield (the surface ground truth) does not contain.
std::vector<Disc> CarrierDiscs(const sim::World& world, double margin_m) {
  std::vector<Disc> discs;
  for (const sim::TagCarrier& c : world.carriers) {
    if (!c.is_static) continue;
    double r = 0.0;
    for (const sim::Box& b : c.boxes) {
      r = std::max(r, b.center_carrier.head<2>().norm() + 0.5 * b.size_m.head<2>().norm());
    }
    discs.push_back({c.T_world_carrier.translation().head<2>(), r + margin_m});
  }
  return discs;
}

bool NearCarrier(const std::vector<Disc>& discs, const Eigen::Vector2d& xy) {
  return std::any_of(discs.begin(), discs.end(),
                     [&xy](const Disc& d) { return (xy - d.centre).norm() <= d.radius_m; });
}

// Lowest and highest terrain over the square cell of side `size_m` at xy.
std::pair<double, double> HeightRange(const sim::Heightfield& terrain, const Eigen::Vector2d& xy,
                                      double size_m) {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  for (int j = 0; j < 5; ++j) {
    for (int i = 0; i < 5; ++i) {
      const double x = xy.x() + size_m * (i / 4.0 - 0.5);
      const double y = xy.y() + size_m * (j / 4.0 - 0.5);
      const double h = terrain.HeightAt(x, y);
      lo = std::min(lo, h);
      hi = std::max(hi, h);
    }
  }
  return {lo, hi};
}

// Calls fn(centre, occupied) for every finest-resolution voxel the tree
// knows (pruned leaves expanded).
template <typename Fn>
void ForEachVoxel(const octomap::OcTree& tree, Fn&& fn) {
  const double res = tree.getResolution();
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
    const bool occupied = tree.isNodeOccupied(*it);
    const double size = it.getSize();
    const int n = std::max(1, static_cast<int>(std::lround(size / res)));
    const octomap::point3d c = it.getCoordinate();
    for (int k = 0; k < n; ++k) {
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
          const Eigen::Vector3d p(static_cast<double>(c.x()) - 0.5 * size + res * (i + 0.5),
                                  static_cast<double>(c.y()) - 0.5 * size + res * (j + 0.5),
                                  static_cast<double>(c.z()) - 0.5 * size + res * (k + 0.5));
          fn(p, occupied);
        }
      }
    }
  }
}

void ScoreOccupancy(const sim::World& world, const octomap::OcTree& map, const MapQualityOptions& o,
                    MapQuality* q) {
  const std::vector<Disc> carriers = CarrierDiscs(world, o.carrier_margin_m);
  const double res = map.getResolution();
  // Per column: bit 0 observed, bit 1 hit.
  std::unordered_map<int64_t, uint8_t> columns;
  ForEachVoxel(map, [&](const Eigen::Vector3d& p, bool occupied) {
    const Eigen::Vector2d xy = p.head<2>();
    if (!world.terrain.Contains(xy.x(), xy.y()) || NearCarrier(carriers, xy)) return;
    const auto [lo, hi] = HeightRange(world.terrain, xy, res);
    const bool on_surface = hi >= p.z() - 0.5 * res - o.surface_tolerance_m &&
                            lo <= p.z() + 0.5 * res + o.surface_tolerance_m;
    if (occupied) {
      ++q->occupied_voxels;
      if (on_surface) ++q->occupied_on_surface;
    }
    const int64_t key = CellKey(static_cast<int64_t>(std::floor(xy.x() / res)),
                                static_cast<int64_t>(std::floor(xy.y() / res)));
    const double h = world.terrain.HeightAt(xy.x(), xy.y());
    uint8_t& flags = columns[key];
    if (std::abs(p.z() - h) <= o.observed_band_m) flags |= 1;
    if (occupied && on_surface) flags |= 2;
  });
  for (const auto& [key, flags] : columns) {
    if ((flags & 1) == 0) continue;
    ++q->observed_columns;
    if ((flags & 2) != 0) ++q->observed_columns_hit;
  }
  q->map_precision = q->occupied_voxels > 0 ? static_cast<double>(q->occupied_on_surface) /
                                                  static_cast<double>(q->occupied_voxels)
                                            : kNaN;
  q->map_recall = q->observed_columns > 0 ? static_cast<double>(q->observed_columns_hit) /
                                                static_cast<double>(q->observed_columns)
                                          : kNaN;
}

// Whether some camera saw the obstacle at (xy, ground height z) within
// range and field of view from where stereo resolves its relief: relief >
// h_max + the stereo error of the height difference between its foot and
// its top.
bool Resolved(const std::vector<Eigen::Isometry3d>& cameras,
              const std::vector<Eigen::Isometry3d>& T_cam_world,
              const mapping::StereoErrorModel& model, const Eigen::Vector2d& xy, double z,
              double relief_m, double h_max_m, const MapQualityOptions& o) {
  if (relief_m <= h_max_m) return false;
  const Eigen::Vector3d foot(xy.x(), xy.y(), z);
  const Eigen::Vector3d top = foot + relief_m * Eigen::Vector3d::UnitZ();
  for (std::size_t i = 0; i < cameras.size(); ++i) {
    const Eigen::Isometry3d& T = cameras[i];
    const Eigen::Vector2d to = xy - T.translation().head<2>();
    const double range = to.norm();
    if (range > o.obstacle_view_range_m || range < 1e-6) continue;
    const Eigen::Vector2d forward = (T.linear() * Eigen::Vector3d::UnitZ()).head<2>();
    if (forward.norm() < 1e-6) continue;
    const double cos_angle = forward.normalized().dot(to / range);
    if (cos_angle < std::cos(o.camera_half_fov_rad)) continue;
    const Eigen::Vector3d foot_cam = T_cam_world[i] * foot;
    const Eigen::Vector3d top_cam = T_cam_world[i] * top;
    if (foot_cam.z() <= 0.0 || top_cam.z() <= 0.0) continue;
    const Eigen::Vector3d up_cam = T_cam_world[i].linear() * Eigen::Vector3d::UnitZ();
    if (relief_m > h_max_m + model.HeightDifferenceSigma(top_cam, foot_cam, up_cam)) {
      return true;
    }
  }
  return false;
}

// Relief of the obstacle at truth cell (ix, iy), by the obstacle rule's
// own measures (sim::ComputeObstacleCells): the tallest rock covering it;
// else the larger of the drop below it within the drop window and the
// step within the step window once the plane fitted over the slope window
// is taken out (a slope alone is no step).
double Relief(const sim::World& world, const std::vector<const sim::Rock*>& rocks,
              const sim::ObstacleGrid& truth, const sim::ObstacleRuleOptions& rule, int64_t ix,
              int64_t iy) {
  const double res = truth.resolution_m;
  const double x = truth.origin_xy.x() + static_cast<double>(ix) * res;
  const double y = truth.origin_xy.y() + static_cast<double>(iy) * res;
  double rock_m = 0.0;
  for (const sim::Rock* rock : rocks) {
    if (RockBumpHeight(*rock, x, y) > 0.0) rock_m = std::max(rock_m, rock->height_m);
  }
  if (rock_m > 0.0) return rock_m;
  const sim::Heightfield& terrain = world.terrain;
  const auto height = [&terrain](int64_t i, int64_t j) {
    return static_cast<double>(
        terrain.HeightAtCell(static_cast<int>(std::clamp<int64_t>(i, 0, terrain.cols() - 1)),
                             static_cast<int>(std::clamp<int64_t>(j, 0, terrain.rows() - 1))));
  };
  const auto half_cells = [res](double window_m) {
    return std::max<int64_t>(1, std::lround(0.5 * window_m / res));
  };
  const double centre = height(ix, iy);
  double drop = 0.0;
  const int64_t k_drop = half_cells(rule.negative_window_m);
  for (int64_t j = -k_drop; j <= k_drop; ++j) {
    for (int64_t i = -k_drop; i <= k_drop; ++i)
      drop = std::max(drop, centre - height(ix + i, iy + j));
  }
  // Least-squares plane on the regular grid: dz/dx = sum(i h) / (res sum(i^2)).
  const int64_t k_slope = half_cells(rule.slope_window_m);
  double sum_ih = 0.0, sum_jh = 0.0, sum_i2 = 0.0;
  for (int64_t j = -k_slope; j <= k_slope; ++j) {
    for (int64_t i = -k_slope; i <= k_slope; ++i) {
      const double h = height(ix + i, iy + j);
      sum_ih += static_cast<double>(i) * h;
      sum_jh += static_cast<double>(j) * h;
      sum_i2 += static_cast<double>(i * i);
    }
  }
  const double gx = sum_ih / sum_i2;  // per cell
  const double gy = sum_jh / sum_i2;
  const int64_t k_step = half_cells(rule.step_window_m);
  double lo = 0.0, hi = 0.0;
  for (int64_t j = -k_step; j <= k_step; ++j) {
    for (int64_t i = -k_step; i <= k_step; ++i) {
      const double residual = height(ix + i, iy + j) - centre - gx * static_cast<double>(i) -
                              gy * static_cast<double>(j);
      lo = std::min(lo, residual);
      hi = std::max(hi, residual);
    }
  }
  return std::max(drop, hi - lo);
}

void ScoreObstacles(const sim::World& world, const sim::ObstacleGrid& truth,
                    const sim::ObstacleRuleOptions& rule, const mapping::PointCloud& cloud,
                    const std::vector<Eigen::Isometry3d>& cameras,
                    const mapping::RectifiedStereo& head, const MapQualityOptions& o,
                    MapQuality* q) {
  const mapping::StereoErrorModel model(head, o.pixel_error_px);
  std::vector<Eigen::Isometry3d> T_cam_world;
  T_cam_world.reserve(cameras.size());
  for (const Eigen::Isometry3d& T : cameras) T_cam_world.push_back(T.inverse());
  const double res = truth.resolution_m;
  const auto cell_of = [&](const Eigen::Vector3f& p, int64_t* ix, int64_t* iy) {
    *ix =
        static_cast<int64_t>(std::floor((static_cast<double>(p.x()) - truth.origin_xy.x()) / res));
    *iy =
        static_cast<int64_t>(std::floor((static_cast<double>(p.y()) - truth.origin_xy.y()) / res));
    return *ix >= 0 && *iy >= 0 && *ix < truth.cols && *iy < truth.rows;
  };
  const auto is_obstacle = [&](int64_t ix, int64_t iy) {
    if (ix < 0 || iy < 0 || ix >= truth.cols || iy >= truth.rows) return false;
    const sim::ObstacleCode c = truth.CodeAt(static_cast<int>(ix), static_cast<int>(iy));
    return c == sim::ObstacleCode::kPositive || c == sim::ObstacleCode::kNegative;
  };
  const std::vector<Disc> posts = CarrierDiscs(world, o.obstacle_radius_m);
  const int reach = static_cast<int>(std::ceil(o.obstacle_radius_m / res));
  const double reach2 = (o.obstacle_radius_m / res) * (o.obstacle_radius_m / res);
  std::unordered_set<int64_t> seen;
  std::unordered_set<int64_t> flagged;
  int64_t min_x = truth.cols, min_y = truth.rows, max_x = -1, max_y = -1;
  for (const mapping::CloudPoint& p : cloud) {
    int64_t ix = 0;
    int64_t iy = 0;
    if (!cell_of(p.p_submap_m, &ix, &iy)) continue;
    seen.insert(CellKey(ix, iy));
    min_x = std::min(min_x, ix);
    min_y = std::min(min_y, iy);
    max_x = std::max(max_x, ix);
    max_y = std::max(max_y, iy);
    if (!p.obstacle) continue;
    ++q->obstacle_points;
    flagged.insert(CellKey(ix, iy));
    // A landmark post is an obstacle as much as a rock, though the
    // heightfield and so the obstacle grid do not hold it.
    bool near = NearCarrier(posts, p.p_submap_m.head<2>().cast<double>());
    for (int dy = -reach; dy <= reach && !near; ++dy) {
      for (int dx = -reach; dx <= reach && !near; ++dx) {
        near = dx * dx + dy * dy <= reach2 && is_obstacle(ix + dx, iy + dy);
      }
    }
    if (near) ++q->obstacle_points_true;
  }
  // The rocks that reach into the mapped area.
  std::vector<const sim::Rock*> rocks;
  const double x_lo = truth.origin_xy.x() + static_cast<double>(min_x) * res;
  const double x_hi = truth.origin_xy.x() + static_cast<double>(max_x + 1) * res;
  const double y_lo = truth.origin_xy.y() + static_cast<double>(min_y) * res;
  const double y_hi = truth.origin_xy.y() + static_cast<double>(max_y + 1) * res;
  for (const sim::Rock& rock : world.rocks) {
    const double r = RockOuterRadius(rock);
    if (rock.center_xy.x() + r >= x_lo && rock.center_xy.x() - r <= x_hi &&
        rock.center_xy.y() + r >= y_lo && rock.center_xy.y() - r <= y_hi) {
      rocks.push_back(&rock);
    }
  }
  for (int64_t iy = min_y; iy <= max_y; ++iy) {
    for (int64_t ix = min_x; ix <= max_x; ++ix) {
      if (!is_obstacle(ix, iy)) continue;
      bool observed = false;
      for (int dy = -1; dy <= 1 && !observed; ++dy) {
        for (int dx = -1; dx <= 1 && !observed; ++dx)
          observed = seen.count(CellKey(ix + dx, iy + dy)) > 0;
      }
      if (!observed) continue;
      const Eigen::Vector2d cell(truth.origin_xy.x() + (static_cast<double>(ix) + 0.5) * res,
                                 truth.origin_xy.y() + (static_cast<double>(iy) + 0.5) * res);
      const double z = static_cast<double>(
          world.terrain.HeightAtCell(static_cast<int>(ix), static_cast<int>(iy)));
      const double relief = Relief(world, rocks, truth, rule, ix, iy);
      if (!Resolved(cameras, T_cam_world, model, cell, z, relief, rule.step_height_m, o)) {
        continue;
      }
      ++q->truth_obstacle_cells_observed;
      bool found = false;
      for (int dy = -reach; dy <= reach && !found; ++dy) {
        for (int dx = -reach; dx <= reach && !found; ++dx) {
          found = dx * dx + dy * dy <= reach2 && flagged.count(CellKey(ix + dx, iy + dy)) > 0;
        }
      }
      if (found) ++q->truth_obstacle_cells_found;
    }
  }
  q->obstacle_precision = q->obstacle_points > 0 ? static_cast<double>(q->obstacle_points_true) /
                                                       static_cast<double>(q->obstacle_points)
                                                 : kNaN;
  q->obstacle_recall = q->truth_obstacle_cells_observed > 0
                           ? static_cast<double>(q->truth_obstacle_cells_found) /
                                 static_cast<double>(q->truth_obstacle_cells_observed)
                           : kNaN;
}

}  // namespace

RectifiedHead RectifiedHeadOf(const sim::StereoCameraOptions& camera) {
  const std::optional<calib::StereoRectifier> r = calib::StereoRectifier::Create(
      CameraModelOf(camera, camera.T_body_cam0), CameraModelOf(camera, camera.T_body_cam1()));
  if (!r) throw std::invalid_argument("RectifiedHeadOf: the simulated head does not rectify");
  RectifiedHead head;
  head.stereo.width_px = r->image_size().width;
  head.stereo.height_px = r->image_size().height;
  head.stereo.focal_px = r->intrinsics().fx;
  head.stereo.cx_px = r->intrinsics().cx;
  head.stereo.cy_px = r->intrinsics().cy;
  head.stereo.baseline_m = r->baseline_m();
  head.stereo.Validate();
  head.T_body_cam0rect = r->T_body_cam0rect();
  return head;
}

MapQuality EvaluateMap(const sim::World& world, const sim::ObstacleGrid& truth,
                       const sim::ObstacleRuleOptions& rule, const octomap::OcTree& map_world,
                       const mapping::PointCloud& cloud_world,
                       const std::vector<Eigen::Isometry3d>& T_world_cameras,
                       const mapping::RectifiedStereo& head, const MapQualityOptions& options) {
  MapQuality q;
  ScoreOccupancy(world, map_world, options, &q);
  ScoreObstacles(world, truth, rule, cloud_world, T_world_cameras, head, options, &q);
  return q;
}

ContentShift EstimateContentShift(const sim::Heightfield& terrain,
                                  const std::vector<PlacedCloud>& clouds) {
  constexpr double kMaxHeightErrorM = 0.1;  // rock overhangs, stereo outliers
  constexpr double kMaxSlope = 1.0;         // steeper flanks are too nonlinear
  Eigen::Matrix3d AtA = Eigen::Matrix3d::Zero();
  Eigen::Vector3d Atb = Eigen::Vector3d::Zero();
  ContentShift out;
  for (const PlacedCloud& placed : clouds) {
    if (placed.cloud == nullptr) continue;
    const Eigen::Isometry3d& T = placed.T_world_submap;
    const Eigen::Vector2d forward = T.linear().col(0).head<2>().normalized();
    const Eigen::Vector2d left(-forward.y(), forward.x());
    for (const mapping::CloudPoint& c : *placed.cloud) {
      const Eigen::Vector3d p = T * c.p_submap_m.cast<double>();
      if (!terrain.Contains(p.x(), p.y())) continue;
      const double error_m = p.z() - terrain.HeightAt(p.x(), p.y());
      const Eigen::Vector2d g = terrain.GradientAt(p.x(), p.y());
      if (std::abs(error_m) > kMaxHeightErrorM || g.norm() > kMaxSlope) continue;
      // error = -g.forward d_forward - g.left d_left + d_up
      const Eigen::Vector3d a(-g.dot(forward), -g.dot(left), 1.0);
      AtA += a * a.transpose();
      Atb += a * error_m;
      ++out.points;
    }
  }
  // Both slope directions must be seen, or forward and left are not
  // separable (flat ground says nothing about a horizontal shift).
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(AtA);
  if (out.points < 100 || eig.eigenvalues()(0) < 1e-4 * static_cast<double>(out.points)) {
    return out;
  }
  const Eigen::Vector3d d = AtA.ldlt().solve(Atb);
  out.ok = true;
  out.forward_m = d(0);
  out.left_m = d(1);
  out.up_m = d(2);
  return out;
}

}  // namespace rover::sim::experiments
