#ifndef ROVER_TESTS_MAPPING_LOOP_LOOP_TEST_SCENE_H_
#define ROVER_TESTS_MAPPING_LOOP_LOOP_TEST_SCENE_H_

// Synthetic gravity-aligned submaps for the loop-closure tests and
// bench/mapping: a world of gently sloped ground with rocks (spheres, partly
// buried) and optional walls (boxes), seen by the simulator's stereo head
// (half resolution) along a short drive. Disparities are exact ray casts
// plus Gaussian disparity noise, so the range error grows with the square
// of the distance as in stereo; points on rocks and walls carry the
// obstacle flag. The images go through the real Submap (OctoMap voxel space
// and voxel-centroid cloud) in the submap's own frame, whose pose in the
// world T_world_submap is gravity-aligned and known, so T_a_b between two
// submaps is known exactly.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "core/geometry/yaw.h"
#include "mapping/depth/depth_image.h"
#include "mapping/depth/stereo_error_model.h"
#include "mapping/submap/submap.h"
#include "tests/mapping/mapping_test_head.h"

namespace rover::mapping::testing {

/// A rock: an ellipsoid, partly sunk into the ground. Irregular shapes
/// matter: a sphere is symmetric about its vertical axis, so a match on
/// spheres alone leaves yaw about a rock free.
struct Rock {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d semi_axes_m = Eigen::Vector3d::Ones();
  Eigen::Matrix3d R_world_rock = Eigen::Matrix3d::Identity();
  /// Bounding radius (largest semi-axis).
  double radius_m = 0.0;
};

/// Axis-aligned box (a wall).
struct Block {
  Eigen::Vector3d min = Eigen::Vector3d::Zero();
  Eigen::Vector3d max = Eigen::Vector3d::Zero();
};

struct LoopWorld {
  /// Ground plane z = slope_x x + slope_y y.
  double slope_x = 0.01;
  double slope_y = -0.015;
  std::vector<Rock> rocks;
  std::vector<Block> blocks;

  double GroundZ(double x, double y) const { return slope_x * x + slope_y * y; }
};

/// Rocks scattered over [x0, x1] x [y0, y1], `per_m2` of them per square
/// metre: ellipsoids of size 0.12-0.45 m, axes 0.5-1.3 times that, any yaw
/// and up to 20 deg of tilt, sunk by 0-40 % of their height.
inline void ScatterRocks(double x0, double x1, double y0, double y1, double per_m2, uint64_t seed,
                         LoopWorld* world) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> ux(x0, x1), uy(y0, y1), ur(0.12, 0.45), us(0.0, 0.4),
      ua(0.5, 1.3), uyaw(-M_PI, M_PI), utilt(-0.35, 0.35);
  const int n = static_cast<int>(per_m2 * (x1 - x0) * (y1 - y0));
  for (int i = 0; i < n; ++i) {
    Rock r;
    const double size = ur(rng);
    r.semi_axes_m = size * Eigen::Vector3d(ua(rng), ua(rng), 0.5 * ua(rng) + 0.35);
    r.R_world_rock = (Eigen::AngleAxisd(uyaw(rng), Eigen::Vector3d::UnitZ()) *
                      Eigen::AngleAxisd(utilt(rng), Eigen::Vector3d::UnitX()))
                         .toRotationMatrix();
    r.radius_m = r.semi_axes_m.maxCoeff();
    const double x = ux(rng);
    const double y = uy(rng);
    r.centre = {x, y, world->GroundZ(x, y) + r.semi_axes_m.z() * (1.0 - us(rng))};
    world->rocks.push_back(r);
  }
}

/// What a ray hit.
struct Hit {
  double range = std::numeric_limits<double>::infinity();
  bool obstacle = false;
};

inline Hit CastRay(const Eigen::Vector3d& c, const Eigen::Vector3d& d, const LoopWorld& w,
                   const std::vector<int>& rocks_near) {
  Hit hit;
  const Eigen::Vector3d n(-w.slope_x, -w.slope_y, 1.0);
  const double nd = n.dot(d);
  if (nd < 0.0) {
    const double t = -n.dot(c) / nd;
    if (t > 0.0) hit.range = t;
  }
  for (int i : rocks_near) {
    const Rock& rock = w.rocks[static_cast<std::size_t>(i)];
    // Bounding sphere first, then the ray in the rock's unit-sphere frame
    // (t is the same parameter in both frames).
    const Eigen::Vector3d oc = c - rock.centre;
    const double bb = oc.dot(d);
    if (bb * bb - (oc.squaredNorm() - rock.radius_m * rock.radius_m) < 0.0) continue;
    const Eigen::Vector3d o = (rock.R_world_rock.transpose() * oc).cwiseQuotient(rock.semi_axes_m);
    const Eigen::Vector3d e = (rock.R_world_rock.transpose() * d).cwiseQuotient(rock.semi_axes_m);
    const double qa = e.squaredNorm();
    const double qb = o.dot(e);
    const double disc = qb * qb - qa * (o.squaredNorm() - 1.0);
    if (disc < 0.0) continue;
    const double t = (-qb - std::sqrt(disc)) / qa;
    if (t > 0.0 && t < hit.range) hit = {t, true};
  }
  for (const Block& box : w.blocks) {
    double t0 = 0.0;
    double t1 = std::numeric_limits<double>::infinity();
    bool miss = false;
    for (int a = 0; a < 3 && !miss; ++a) {
      if (std::abs(d[a]) < 1e-12) {
        miss = c[a] < box.min[a] || c[a] > box.max[a];
        continue;
      }
      double ta = (box.min[a] - c[a]) / d[a];
      double tb = (box.max[a] - c[a]) / d[a];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
      miss = t0 > t1;
    }
    if (!miss && t0 > 0.0 && t0 < hit.range) hit = {t0, true};
  }
  // Points barely above the ground are not obstacles (a sunk rock's rim).
  if (hit.obstacle) {
    const Eigen::Vector3d p = c + hit.range * d;
    hit.obstacle = p.z() - w.GroundZ(p.x(), p.y()) > 0.05;
  }
  return hit;
}

struct RenderSettings {
  int head_factor = 2;  ///< SimulatorHead(2): 376x240
  double disparity_noise_px = std::getenv("NOISE") ? std::atof(std::getenv("NOISE")) : 0.25;
  double stereo_range_m = 7.0;
  double max_depth_sigma_m = 0.3;
};

/// One depth image and its obstacle mask from camera pose T_world_cam.
inline void RenderFrame(const LoopWorld& world, const Eigen::Isometry3d& T_world_cam,
                        const RenderSettings& s, std::mt19937_64* rng, DepthImage* depth,
                        std::vector<uint8_t>* mask) {
  const RectifiedStereo head = SimulatorHead(s.head_factor);
  const Eigen::Vector3d c = T_world_cam.translation();
  std::vector<int> near;
  for (std::size_t i = 0; i < world.rocks.size(); ++i) {
    if ((world.rocks[i].centre - c).head<2>().norm() < s.stereo_range_m + 1.0) {
      near.push_back(static_cast<int>(i));
    }
  }
  std::normal_distribution<double> noise(0.0, s.disparity_noise_px);
  cv::Mat disparity(head.height_px, head.width_px, CV_16SC1, cv::Scalar(0));
  std::vector<uint8_t> hit_obstacle(static_cast<std::size_t>(head.width_px * head.height_px), 0);
  for (int v = 0; v < head.height_px; ++v) {
    for (int u = 0; u < head.width_px; ++u) {
      const Eigen::Vector3d ray((u - head.cx_px) / head.focal_px, (v - head.cy_px) / head.focal_px,
                                1.0);
      const Eigen::Vector3d d = T_world_cam.linear() * ray.normalized();
      const Hit hit = CastRay(c, d, world, near);
      if (!(hit.range < s.stereo_range_m)) continue;
      const double z_cam = hit.range / ray.norm();
      const double disparity_px = head.focal_px * head.baseline_m / z_cam + noise(*rng);
      disparity.at<int16_t>(v, u) =
          static_cast<int16_t>(std::lround(16.0 * std::max(0.0, disparity_px)));
      hit_obstacle[static_cast<std::size_t>(v * head.width_px + u)] = hit.obstacle ? 1 : 0;
    }
  }
  const StereoErrorModel model(head, 0.5);
  *depth = DepthImage::FromDisparity(disparity, model, {.max_depth_sigma_m = s.max_depth_sigma_m});
  *mask = std::move(hit_obstacle);
}

/// A rover drive: body poses along a straight line from `start_xy` with
/// heading `yaw_rad`, `frames` frames `step_m` apart, the camera 1 m above
/// the ground pitched down 18 deg.
inline std::vector<Eigen::Isometry3d> StraightDrive(const LoopWorld& world,
                                                    const Eigen::Vector2d& start_xy, double yaw_rad,
                                                    int frames, double step_m) {
  std::vector<Eigen::Isometry3d> cams;
  const Eigen::Vector2d dir(std::cos(yaw_rad), std::sin(yaw_rad));
  for (int i = 0; i < frames; ++i) {
    const Eigen::Vector2d p = start_xy + step_m * i * dir;
    // A slight wobble in heading so that consecutive views differ.
    cams.push_back(CameraPose(p.x(), p.y(), world.GroundZ(p.x(), p.y()) + 1.0,
                              yaw_rad + 0.05 * std::sin(0.7 * i), 18.0));
  }
  return cams;
}

/// The gravity-aligned submap frame at the first camera's position on the
/// ground, heading as the camera.
inline Eigen::Isometry3d SubmapFrameAt(const Eigen::Isometry3d& T_world_cam) {
  const Eigen::Vector3d p = T_world_cam.translation();
  // The camera's optical axis (z) projected on the ground gives the heading.
  const Eigen::Vector3d forward = T_world_cam.linear().col(2);
  return GravityAlignedTransform(p, std::atan2(forward.y(), forward.x()));
}

struct SyntheticSubmap {
  std::unique_ptr<Submap> submap;
  Eigen::Isometry3d T_world_submap = Eigen::Isometry3d::Identity();
};

/// Renders the drive into a finished submap in the frame of its first pose;
/// the submap is `frame_id`'s (index and frame id).
inline SyntheticSubmap BuildSubmap(const LoopWorld& world,
                                   const std::vector<Eigen::Isometry3d>& cams, uint64_t seed,
                                   const RenderSettings& s = {}, uint32_t frame_id = 0) {
  SyntheticSubmap out;
  out.T_world_submap = SubmapFrameAt(cams.front());
  out.submap = std::make_unique<Submap>(frame_id, frame_id, SubmapOptions{});
  std::mt19937_64 rng(seed);
  DepthImage depth;
  std::vector<uint8_t> mask;
  for (const Eigen::Isometry3d& T_world_cam : cams) {
    RenderFrame(world, T_world_cam, s, &rng, &depth, &mask);
    out.submap->Integrate(depth, mask, out.T_world_submap.inverse() * T_world_cam);
  }
  out.submap->Finish();
  return out;
}

/// Translation and rotation error of T against the truth.
struct PoseError {
  double translation_m = 0.0;
  double rotation_rad = 0.0;
};

inline PoseError ErrorOf(const Eigen::Isometry3d& T, const Eigen::Isometry3d& truth) {
  const Eigen::Isometry3d d = truth.inverse() * T;
  return {d.translation().norm(), Eigen::AngleAxisd(d.linear()).angle()};
}

}  // namespace rover::mapping::testing

#endif  // ROVER_TESTS_MAPPING_LOOP_LOOP_TEST_SCENE_H_
