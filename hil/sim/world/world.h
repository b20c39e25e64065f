#ifndef ROVER_HIL_SIM_WORLD_WORLD_H_
#define ROVER_HIL_SIM_WORLD_WORLD_H_

// The simulated planetary site: a procedural heightfield with rocks and a
// crater, an albedo texture, and AprilTag-carrying objects (landmark posts,
// other rovers). Everything is generated from a seed; the same seed gives a
// byte-identical world. Frame "world": x east, y north, z up, metres.
//
// This header is the contract between the world generator (world.cc),
// the renderer (hil/sim/render), the motion model (hil/sim/motion) and the
// ground-truth export.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

namespace rover::sim {

/// A regular grid of heights. Cell (ix, iy) has its sample at
/// origin_xy + resolution_m * (ix, iy); row-major, iy outer.
class Heightfield {
 public:
  Heightfield() = default;
  Heightfield(int cols, int rows, double resolution_m, Eigen::Vector2d origin_xy,
              std::vector<float> heights_m);

  int cols() const { return cols_; }
  int rows() const { return rows_; }
  double resolution_m() const { return resolution_m_; }
  const Eigen::Vector2d& origin_xy() const { return origin_xy_; }
  const std::vector<float>& heights_m() const { return heights_m_; }
  float HeightAtCell(int ix, int iy) const {
    return heights_m_[static_cast<std::size_t>(iy) * static_cast<std::size_t>(cols_) +
                      static_cast<std::size_t>(ix)];
  }
  /// True if (x, y) lies inside the grid.
  bool Contains(double x_m, double y_m) const;
  /// Bilinear height at (x, y); clamped to the border outside the grid.
  double HeightAt(double x_m, double y_m) const;
  /// Gradient (dz/dx, dz/dy) of the bilinear surface.
  Eigen::Vector2d GradientAt(double x_m, double y_m) const;
  /// Unit upward surface normal.
  Eigen::Vector3d NormalAt(double x_m, double y_m) const;
  /// First intersection of the ray origin + t * direction (t >= 0, unit
  /// direction) with the bilinear surface, up to max_range_m. Returns false
  /// if there is none. Accurate to well below 1 mm.
  bool Raycast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
               double max_range_m, double* range_m) const;

 private:
  int cols_ = 0;
  int rows_ = 0;
  double resolution_m_ = 0.05;
  Eigen::Vector2d origin_xy_ = Eigen::Vector2d::Zero();
  std::vector<float> heights_m_;
};

/// Grey albedo over the same area as the terrain, at its own resolution,
/// 0 (black) .. 255 (white). Multi-scale, so features exist from 1 m to 20 m.
struct AlbedoMap {
  int cols = 0;
  int rows = 0;
  double resolution_m = 0.025;
  Eigen::Vector2d origin_xy = Eigen::Vector2d::Zero();
  std::vector<uint8_t> values;  ///< row-major, iy outer
  /// Bilinear albedo in [0, 1].
  double At(double x_m, double y_m) const;
};

/// A rock baked into the heightfield (a positive obstacle).
struct Rock {
  Eigen::Vector2d center_xy;
  double radius_m = 0.2;
  double height_m = 0.2;  ///< above the surrounding ground, 0.1 .. 0.6
};

/// A crater baked into the heightfield; its rim drops by more than 0.3 m
/// (a negative obstacle).
struct Crater {
  Eigen::Vector2d center_xy;
  double radius_m = 5.0;
  double depth_m = 1.0;
  double rim_height_m = 0.4;
};

/// A flat square AprilTag (family 36h11) on some carrier. Tag frame as in the
/// apriltag library: origin at the tag centre, x right, y down, z into the
/// tag (pointing away from a camera that reads it).
struct TagMarker {
  int id = 0;
  double size_m = 0.16;  ///< edge length of the black border square
  std::string carrier;   ///< "post_3", "rover_b", ...
  Eigen::Isometry3d T_carrier_tag = Eigen::Isometry3d::Identity();
};

/// An axis-aligned box in its carrier frame, for rendering posts and rover
/// bodies.
struct Box {
  Eigen::Vector3d center_carrier;
  Eigen::Vector3d size_m;
  double albedo = 0.5;
};

/// A rigid object that carries tags: a landmark post (static) or another
/// rover (its pose is given per frame at render time).
struct TagCarrier {
  std::string name;
  bool is_static = true;
  Eigen::Isometry3d T_world_carrier = Eigen::Isometry3d::Identity();  ///< for static carriers
  std::vector<Box> boxes;
  std::vector<TagMarker> tags;
};

struct WorldOptions {
  double size_m = 128.0;          ///< square side, centred on the origin
  double resolution_m = 0.05;     ///< heightfield cell
  double albedo_resolution_m = 0.025;
  double max_slope_deg = 20.0;
  int rock_count = 400;
  int crater_count = 1;
  int landmark_post_count = 6;
  int other_rover_count = 0;       ///< tag-carrying rovers (moving, posed at render time)
  double tag_size_m = 0.16;
};

/// The whole generated site.
struct World {
  WorldOptions options;
  uint64_t seed = 0;
  Heightfield terrain;
  AlbedoMap albedo;
  std::vector<Rock> rocks;
  std::vector<Crater> craters;
  std::vector<TagCarrier> carriers;  ///< posts first, then other rovers

  /// Generates the world; deterministic in (options, seed).
  static World Generate(const WorldOptions& options, uint64_t seed);
};

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_WORLD_WORLD_H_
