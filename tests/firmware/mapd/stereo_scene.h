#ifndef ROVER_TESTS_FIRMWARE_MAPD_STEREO_SCENE_H_
#define ROVER_TESTS_FIRMWARE_MAPD_STEREO_SCENE_H_

// A stereo head over a textured ground plane with one box on it, rendered
// analytically (exact ray casts, no noise), so that mapd's pipeline can be
// run end to end without the simulator's renderer: SGBM finds the texture,
// the box is a step obstacle, the ground is not.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>

#include <Eigen/Geometry>

#include "core/calib/stereo_rectifier.h"

namespace rover::mapd::testing {

struct StereoScene {
  int width_px = 376;
  int height_px = 240;
  double focal_px = 230.0;
  double baseline_m = 0.11;
  /// Ground plane z (local frame; the body is at z = 0).
  double ground_z_m = -0.7;
  /// The box: x, y extent and height above the ground.
  Eigen::Vector2d box_min_xy{2.3, -0.3};
  Eigen::Vector2d box_max_xy{2.7, 0.3};
  double box_height_m = 0.3;

  /// cam0 on the body: 0.2 m ahead, looking along body x, pitched down 25
  /// deg (OpenCV axes: x right, y down, z forward).
  calib::CameraModel Camera(int index) const {
    calib::CameraModel c;
    c.width_px = width_px;
    c.height_px = height_px;
    c.intrinsics = {focal_px, focal_px, width_px / 2.0, height_px / 2.0};
    Eigen::Matrix3d R_forward;
    R_forward << 0, 0, 1,  //
        -1, 0, 0,          //
        0, -1, 0;
    c.T_body_cam.linear() =
        Eigen::AngleAxisd(25.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix() *
        R_forward;
    c.T_body_cam.translation() = Eigen::Vector3d(0.2, 0.0, 0.0);
    if (index == 1) c.T_body_cam = c.T_body_cam * Eigen::Translation3d(baseline_m, 0.0, 0.0);
    return c;
  }

  /// Range along a unit ray to the first surface, and the hit point.
  std::optional<Eigen::Vector3d> Cast(const Eigen::Vector3d& origin,
                                      const Eigen::Vector3d& dir) const {
    std::optional<Eigen::Vector3d> hit;
    double best = 40.0;
    if (dir.z() < -1e-9) {
      const double t = (ground_z_m - origin.z()) / dir.z();
      if (t > 0.0 && t < best) {
        best = t;
        hit = origin + t * dir;
      }
    }
    // Slab test against the box.
    const Eigen::Vector3d lo(box_min_xy.x(), box_min_xy.y(), ground_z_m);
    const Eigen::Vector3d hi(box_max_xy.x(), box_max_xy.y(), ground_z_m + box_height_m);
    double t0 = 0.0;
    double t1 = best;
    for (int a = 0; a < 3; ++a) {
      if (std::abs(dir[a]) < 1e-12) {
        if (origin[a] < lo[a] || origin[a] > hi[a]) return hit;
        continue;
      }
      double ta = (lo[a] - origin[a]) / dir[a];
      double tb = (hi[a] - origin[a]) / dir[a];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
      if (t0 > t1) return hit;
    }
    return origin + t0 * dir;
  }

  /// Texture: smooth value noise at two scales, so SGBM has something to
  /// match everywhere.
  static uint8_t Texture(const Eigen::Vector3d& p) {
    const double v = 0.6 * Noise(p * 25.0) + 0.4 * Noise(p * 6.0);
    return static_cast<uint8_t>(std::clamp(40.0 + 180.0 * v, 0.0, 255.0));
  }

  /// Renders camera `index` at body pose T_local_body into `out` (packed
  /// mono8 rows).
  void Render(int index, const Eigen::Isometry3d& T_local_body, uint8_t* out) const {
    const calib::CameraModel cam = Camera(index);
    const Eigen::Isometry3d T_local_cam = T_local_body * cam.T_body_cam;
    for (int v = 0; v < height_px; ++v) {
      for (int u = 0; u < width_px; ++u) {
        const Eigen::Vector3d ray_cam((u + 0.5 - width_px / 2.0) / focal_px,
                                      (v + 0.5 - height_px / 2.0) / focal_px, 1.0);
        const Eigen::Vector3d dir = (T_local_cam.linear() * ray_cam).normalized();
        const std::optional<Eigen::Vector3d> p = Cast(T_local_cam.translation(), dir);
        out[v * width_px + u] = p ? Texture(*p) : uint8_t{20};
      }
    }
  }

 private:
  static double Hash(int x, int y, int z) {
    uint32_t h = static_cast<uint32_t>(x) * 73856093u ^ static_cast<uint32_t>(y) * 19349663u ^
                 static_cast<uint32_t>(z) * 83492791u;
    h ^= h >> 13;
    h *= 0x5bd1e995u;
    h ^= h >> 15;
    return static_cast<double>(h & 0xffffu) / 65535.0;
  }
  static double Noise(const Eigen::Vector3d& q) {
    const Eigen::Vector3d f = q.array().floor();
    const Eigen::Vector3d t = q - f;
    const int x = static_cast<int>(f.x());
    const int y = static_cast<int>(f.y());
    const int z = static_cast<int>(f.z());
    double sum = 0.0;
    for (int dz = 0; dz < 2; ++dz) {
      for (int dy = 0; dy < 2; ++dy) {
        for (int dx = 0; dx < 2; ++dx) {
          const double w =
              (dx ? t.x() : 1.0 - t.x()) * (dy ? t.y() : 1.0 - t.y()) * (dz ? t.z() : 1.0 - t.z());
          sum += w * Hash(x + dx, y + dy, z + dz);
        }
      }
    }
    return sum;
  }
};

}  // namespace rover::mapd::testing

#endif  // ROVER_TESTS_FIRMWARE_MAPD_STEREO_SCENE_H_
