#ifndef ROVER_HIL_SIM_WORLD_WORLD_H_
#define ROVER_HIL_SIM_WORLD_WORLD_H_

// The simulated planetary site: a procedural heightfield with rocks and a
// crater, an albedo texture, and AprilTag-carrying objects (landmark posts,
// other rovers). Everything is generated from a seed; the same seed gives a
// byte-identical world. Frame "world": x east, y north, z up, metres.
//
// This header is the contract between the world generator (world.cc),
// the renderer (hil/sim/render), the motion model (hil/sim/motion) and the
// ground-truth export (ground_truth_export.cc).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace rover::sim {

/// A regular grid of heights. Cell (ix, iy) has its sample at
/// origin_xy + resolution_m * (ix, iy); row-major, iy outer.
class Heightfield {
 public:
  Heightfield() = default;
  /// Takes cols * rows heights (row-major, iy outer). Throws std::invalid_argument if the sizes
  /// disagree, the grid has fewer than 2 x 2 samples or the resolution is not positive.
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
  /// Lowest and highest sample; both 0 for an empty grid.
  double min_height_m() const { return min_height_m_; }
  double max_height_m() const { return max_height_m_; }
  /// Coordinates of the last sample, origin_xy + resolution_m * (cols - 1, rows - 1).
  Eigen::Vector2d max_xy() const;

  /// True if (x, y) lies inside the grid (borders included).
  bool Contains(double x_m, double y_m) const;
  /// Bilinear height at (x, y); clamped to the border outside the grid.
  double HeightAt(double x_m, double y_m) const;
  /// Gradient (dz/dx, dz/dy) of the bilinear surface, taken in the cell whose lower-left
  /// sample is floor((x, y) - origin) / resolution (so the piecewise gradient is right-
  /// continuous at cell borders). Outside the grid the component along each clamped axis is 0,
  /// matching HeightAt's clamping.
  Eigen::Vector2d GradientAt(double x_m, double y_m) const;
  /// Unit upward surface normal of the bilinear surface, (-dz/dx, -dz/dy, 1) normalised.
  /// Piecewise constant across cells in one direction; see SmoothNormalAt for shading.
  Eigen::Vector3d NormalAt(double x_m, double y_m) const;
  /// Unit upward normal that is continuous in (x, y): central-difference gradients at the four
  /// surrounding samples, interpolated bilinearly. Meant for shading; for physics use NormalAt.
  Eigen::Vector3d SmoothNormalAt(double x_m, double y_m) const;
  /// First intersection of the ray origin + t * direction (t >= 0, unit
  /// direction) with the bilinear surface, up to max_range_m. Returns false
  /// if there is none. Accurate to well below 1 mm.
  ///
  /// The surface exists only above the grid: rays are clipped to its xy extent. If the origin is
  /// below the surface the hit is at range 0. The grid is walked cell by cell, so no crossing is
  /// skipped however thin; within a cell the height along the ray is an exact quadratic and the
  /// crossing is refined by bisection to < 1e-6 m. A 100 m ray takes about 30 us (-O2).
  bool Raycast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double max_range_m,
               double* range_m) const;

 private:
  int cols_ = 0;
  int rows_ = 0;
  double resolution_m_ = 0.05;
  Eigen::Vector2d origin_xy_ = Eigen::Vector2d::Zero();
  std::vector<float> heights_m_;
  double min_height_m_ = 0.0;
  double max_height_m_ = 0.0;
};

/// Grey albedo over the same area as the terrain, at its own resolution,
/// 0 (black) .. 255 (white). Multi-scale, so features exist from 1 m to 20 m.
/// Sample (ix, iy) is at origin_xy + resolution_m * (ix, iy), like the heightfield's.
struct AlbedoMap {
  int cols = 0;
  int rows = 0;
  double resolution_m = 0.025;
  Eigen::Vector2d origin_xy = Eigen::Vector2d::Zero();
  std::vector<uint8_t> values;  ///< row-major, iy outer
  /// Bilinear albedo in [0, 1]; clamped to the border outside the map, 0 for an empty map.
  double At(double x_m, double y_m) const;
};

/// A rock baked into the heightfield (a positive obstacle).
struct Rock {
  Eigen::Vector2d center_xy;
  double radius_m = 0.2;  ///< nominal footprint radius; see outline_harmonics
  double height_m = 0.2;  ///< above the surrounding ground, 0.1 .. 0.6
  /// Superellipsoid exponent of the radial profile (2: half ellipsoid; larger: blockier).
  double shape_exponent = 2.5;
  /// Outline r(theta) = radius_m * (1 + sum_k a_k cos k theta + b_k sin k theta), k = 1..3,
  /// coefficients in the order a1, b1, a2, b2, a3, b3 (theta from the world x axis).
  std::array<double, 6> outline_harmonics{};
  uint64_t surface_seed = 0;  ///< seeds the lumpy surface and the albedo speckle
};

/// Height the rock adds to the ground at (x, y): 0 outside its outline, height_m at its centre,
/// never above height_m. Exactly the amount baked into World::terrain.
double RockBumpHeight(const Rock& rock, double x_m, double y_m);
/// Largest distance from the rock centre at which RockBumpHeight can be non-zero.
double RockOuterRadius(const Rock& rock);

/// A crater baked into the heightfield; its rim drops by more than 0.3 m
/// (a negative obstacle).
///
/// Radial profile (added to the ground), with d the distance from the centre:
///  * d > radius_m: the ejecta rim, rim_height_m at the crest falling smoothly to 0 at
///    2.5 * radius_m;
///  * radius_m - scarp_width_m < d <= radius_m: a scarp just inside the crest dropping by
///    scarp_drop_m (steeper than 60 degrees: the negative obstacle);
///  * inside: a parabolic bowl down to -depth_m at the centre.
struct Crater {
  Eigen::Vector2d center_xy;
  double radius_m = 5.0;  ///< rim crest radius
  double depth_m = 1.0;   ///< floor below the surrounding ground
  double rim_height_m = 0.4;
  double scarp_drop_m = 0.45;
  double scarp_width_m = 0.2;
};

/// Height the crater adds to the ground at (x, y) (negative inside), per the profile above.
double CraterProfileHeight(const Crater& crater, double x_m, double y_m);
/// Distance from the centre beyond which the crater leaves the ground unchanged.
double CraterOuterRadius(const Crater& crater);

/// A flat square AprilTag (family 36h11) on some carrier. Tag frame as in the
/// apriltag library: origin at the tag centre, x right, y down, z into the
/// tag (pointing away from a camera that reads it).
///
/// The renderer draws the full 10 x 10-cell tag image (white outer ring included), i.e. a
/// square of 1.25 * size_m centred on the origin. Tags sit 1 mm in front of the carrier face
/// they are mounted on, so they never depth-fight with it.
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
///
/// Landmark post frame: origin on the terrain at the post's foot, z up (vertical, not along the
/// terrain normal), random yaw. The pole reaches 0.1 m into the ground so it never floats on a
/// slope; a cubic head centred 0.8 m up carries one tag per side, facing outwards.
///
/// Other rover frame: x forward, y left, z up, origin on the ground plane of its wheels below
/// the body centre. Body 0.8 x 0.6 x 0.4 m with its bottom 0.15 m above the ground; tags on the
/// four sides and on top. The motion model supplies T_world_carrier for it per frame.
struct TagCarrier {
  std::string name;
  bool is_static = true;
  Eigen::Isometry3d T_world_carrier = Eigen::Isometry3d::Identity();  ///< for static carriers
  std::vector<Box> boxes;
  std::vector<TagMarker> tags;
};

struct WorldOptions {
  double size_m = 128.0;       ///< square side, centred on the origin
  double resolution_m = 0.05;  ///< heightfield cell
  double albedo_resolution_m = 0.025;
  double max_slope_deg = 20.0;  ///< over 0.5 m baselines, away from rocks and craters
  int rock_count = 400;         ///< fewer are placed if the area is too crowded
  int crater_count = 1;
  int landmark_post_count = 6;
  int other_rover_count = 0;  ///< tag-carrying rovers (moving, posed at render time)
  /// The simulated rover itself ("rover_a") carries tags too, as the last
  /// moving carrier, so other rovers can see it (mutual sightings).
  bool recording_rover_carries_tags = false;
  double tag_size_m = 0.16;        ///< tags on landmark posts
  double rover_tag_size_m = 0.24;  ///< tags on other rovers
  double clear_radius_m = 3.0;     ///< around the origin (the rover start): no rocks, no posts
  /// Centres of the first craters, overriding their random placement (a
  /// scenario puts its crater beside its route).
  std::vector<Eigen::Vector2d> crater_centers_xy_m;
  /// Feet of the first landmark posts, overriding their random placement (a
  /// scenario puts its posts beside its route, to be seen and seen again);
  /// their headings stay random. At most landmark_post_count.
  std::vector<Eigen::Vector2d> landmark_posts_xy_m;
  /// Polylines the rovers drive along: no rock or post within
  /// clear_path_half_width_m of them, so routes never cross an obstacle.
  std::vector<std::vector<Eigen::Vector2d>> clear_paths_xy_m;
  double clear_path_half_width_m = 0.8;
};

/// Distance from `xy` to the nearest clear path of `options` (infinity if none).
double DistanceToClearPaths(const WorldOptions& options, const Eigen::Vector2d& xy);

/// The whole generated site.
struct World {
  WorldOptions options;
  uint64_t seed = 0;
  Heightfield terrain;
  AlbedoMap albedo;
  std::vector<Rock> rocks;
  std::vector<Crater> craters;
  std::vector<TagCarrier> carriers;  ///< posts first, then other rovers

  /// Generates the world; deterministic in (options, seed): the same inputs give the same bytes
  /// on every run (all randomness is integer-hash based or raw std::mt19937_64 output).
  /// Size: round(size_m / resolution_m) + 1 samples per side, centred on the origin.
  /// Throws std::invalid_argument for non-positive sizes or resolutions, negative counts, or more
  /// tags than the 587 ids of family 36h11.
  static World Generate(const WorldOptions& options, uint64_t seed);
};

/// Builds a landmark post carrier (static) named `name` with 4 tags, ids first_tag_id ..
/// first_tag_id + 3 on its +x, +y, -x, -y head faces, standing at T_world_carrier.
TagCarrier MakeLandmarkPost(const std::string& name, int first_tag_id, double tag_size_m,
                            const Eigen::Isometry3d& T_world_carrier);
/// Builds another rover carrier (not static) named `name` with 5 tags, ids first_tag_id ..
/// first_tag_id + 4 on its front, left, back, right and top faces.
TagCarrier MakeOtherRover(const std::string& name, int first_tag_id, double tag_size_m);

// ---------------------------------------------------------------------------
// Obstacle ground truth

/// Cell codes of the obstacle grid.
enum class ObstacleCode : uint8_t {
  kFree = 0,
  kPositive = 1,  ///< a rock or a step higher than a wheel can climb
  kSlope = 2,     ///< steeper than the rover may drive
  kNegative = 3,  ///< the top edge of a drop (crater scarp, cliff)
};

/// Parameters of the obstacle rule (see ComputeObstacleCells). Windows are squares centred on
/// the cell, their half-width rounded to whole cells.
struct ObstacleRuleOptions {
  double rock_min_height_m = 0.01;  ///< a rock cell counts when the rock adds more than this
  double step_window_m = 0.3;       ///< robot scale: about a wheel's contact patch and travel
  double step_height_m = 0.1;       ///< largest step a wheel climbs
  double slope_window_m = 0.5;      ///< plane fit for the slope and for detrending steps
  double max_slope_deg = 25.0;      ///< steepest traversable slope
  double negative_window_m = 0.5;   ///< how far ahead a wheel may find the ground gone
  double negative_drop_m = 0.3;     ///< deeper than this is a negative obstacle
};

/// One code per heightfield sample (same grid as World::terrain).
struct ObstacleGrid {
  int cols = 0;
  int rows = 0;
  double resolution_m = 0.05;
  Eigen::Vector2d origin_xy = Eigen::Vector2d::Zero();
  std::vector<uint8_t> codes;  ///< ObstacleCode values, row-major, iy outer
  ObstacleCode CodeAt(int ix, int iy) const {
    return static_cast<ObstacleCode>(
        codes[static_cast<std::size_t>(iy) * static_cast<std::size_t>(cols) +
              static_cast<std::size_t>(ix)]);
  }
};

/// Classifies every heightfield sample. The first rule that applies sets the code:
///  1. kPositive: a rock adds more than rock_min_height_m here (rocks are positive obstacles
///     whole, flat tops included; uses the rock ground truth, not just the heights);
///  2. kNegative: within negative_window_m the terrain lies more than negative_drop_m below this
///     sample, i.e. the sample is at the top edge of a drop where a wheel would fall;
///  3. kPositive: after removing the least-squares plane fitted over slope_window_m, the heights
///     within step_window_m span more than step_height_m (a step, independent of the slope);
///  4. kSlope: that plane is steeper than max_slope_deg;
///  5. kFree otherwise.
/// Windows are clipped at the grid border. Takes about 1 s for the default 128 m world.
ObstacleGrid ComputeObstacleCells(const World& world, const ObstacleRuleOptions& rule = {});

/// Human-readable statement of the rule with its parameters, as written to obstacles.yaml.
std::string DescribeObstacleRule(const ObstacleRuleOptions& rule);

// ---------------------------------------------------------------------------
// Ground-truth export

/// Writes the world's ground truth into `dir` (created if missing):
///  * world.yaml: seed and options;
///  * heightfield.bin: raw little-endian float32 heights, row-major, iy outer, no header;
///    heightfield.yaml: its layout (cols, rows, resolution_m, origin, frame, min/max);
///  * albedo.png (8-bit grey, PNG row r = grid row iy = r, so north is down when viewed as an
///    image) and albedo.yaml (its grid);
///  * obstacles.png (one ObstacleCode per pixel, same layout as the heightfield) and
///    obstacles.yaml (the rule in words and numbers, the codes, cell counts);
///  * tags.csv: carrier,is_static,tag_id,size_m,frame,px,py,pz,qw,qx,qy,qz, one row per tag;
///    frame "world" (static carriers) gives T_world_tag, frame "carrier" (moving carriers)
///    T_carrier_tag; quaternions with qw >= 0;
///  * carriers.csv (T_world_carrier of static carriers), boxes.csv (every carrier's boxes in
///    its frame), rocks.csv (all Rock fields and the terrain height at the centre), craters.csv.
/// Numbers are in shortest round-trip form. The bytes depend only on (world, rule), so the
/// same seed exports identical files. Throws std::runtime_error if a file cannot be written.
void ExportWorldGroundTruth(const World& world, const std::string& dir,
                            const ObstacleRuleOptions& rule = {});

/// mapd's marker file (mapping::TagObserverOptions::Load) for the world's
/// tags, as a site survey would give it: family tag36h11; every tag of
/// landmark post k is a marker of landmark k with its T_carrier_tag (so the
/// four faces are one landmark); the tags of moving carriers are robot
/// markers, numbered as the team numbers its rovers ("rover_a" 0, the other
/// rovers 1, 2, ... in world order). A robot marker's pose is in that rover's
/// body (IMU) frame, which its filter estimates: a moving carrier's frame
/// sits `rover_body_height_m[robot]` below it (RoverTrajectoryOptions::
/// body_height_m; a robot not in the map: 0, the carrier frame).
std::string TagMarkerFile(const World& world,
                          const std::map<int, double>& rover_body_height_m = {});

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_WORLD_WORLD_H_
