// World::Generate: terrain (fBm undulation scaled to the slope limit, cm-scale
// roughness, a crater, rocks), landmark posts and other rovers, albedo.

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "hil/sim/world/albedo.h"
#include "hil/sim/world/noise.h"
#include "hil/sim/world/world.h"

namespace rover::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kTag36h11Ids = 587;

// Independent random streams drawn from one seed.
constexpr uint64_t kLayerUndulation = 1;
constexpr uint64_t kLayerRoughness = 2;
constexpr uint64_t kLayerPlacement = 3;

// Baseline over which slopes are limited, as a rover's wheelbase sees them.
constexpr double kSlopeBaselineM = 0.5;
// Kept below the slope limit so interpolation between samples cannot exceed it.
constexpr double kSlopeMarginDeg = 0.5;

int SamplesPerSide(double size_m, double resolution_m) {
  return static_cast<int>(std::lround(size_m / resolution_m)) + 1;
}

std::size_t Index(int ix, int iy, int cols) {
  return static_cast<std::size_t>(iy) * static_cast<std::size_t>(cols) +
         static_cast<std::size_t>(ix);
}

void Validate(const WorldOptions& o) {
  const auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("WorldOptions: ") + what);
  };
  require(o.resolution_m > 0.0 && o.albedo_resolution_m > 0.0, "resolutions must be positive");
  require(o.size_m >= 20.0 * o.resolution_m && o.size_m >= 20.0 * o.albedo_resolution_m,
          "size_m must span at least 20 cells");
  require(o.size_m / o.resolution_m <= 20000.0 && o.size_m / o.albedo_resolution_m <= 40000.0,
          "grid too large");
  require(o.max_slope_deg > 1.0 && o.max_slope_deg < 80.0, "max_slope_deg must be in (1, 80)");
  require(o.rock_count >= 0 && o.crater_count >= 0 && o.landmark_post_count >= 0 &&
              o.other_rover_count >= 0,
          "counts must not be negative");
  require(o.tag_size_m > 0.0 && o.rover_tag_size_m > 0.0 && o.rover_tag_size_m <= 0.3,
          "tag sizes must be positive (rover tags at most 0.3 m, the body is 0.4 m high)");
  require(4 * o.landmark_post_count +
                  5 * (o.other_rover_count + (o.recording_rover_carries_tags ? 1 : 0)) <=
              kTag36h11Ids,
          "more tags than the 587 ids of family 36h11");
  require(o.clear_radius_m >= 0.0, "clear_radius_m must not be negative");
}

// A direction drawn by rejection in the unit disc: no trigonometry, so the
// draw is the same wherever it runs.
Eigen::Vector2d RandomUnitVector(SeededRandom& rng) {
  while (true) {
    const Eigen::Vector2d v(rng.Uniform(-1.0, 1.0), rng.Uniform(-1.0, 1.0));
    const double n2 = v.squaredNorm();
    if (n2 > 1e-4 && n2 <= 1.0) return v / std::sqrt(n2);
  }
}

}  // namespace

double DistanceToClearPaths(const WorldOptions& options, const Eigen::Vector2d& xy) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& path : options.clear_paths_xy_m) {
    for (std::size_t i = 0; i + 1 < path.size(); ++i) {
      const Eigen::Vector2d d = path[i + 1] - path[i];
      const double length2 = d.squaredNorm();
      const double u = length2 > 0 ? std::clamp((xy - path[i]).dot(d) / length2, 0.0, 1.0) : 0.0;
      best = std::min(best, (path[i] + u * d - xy).norm());
    }
    if (path.size() == 1) best = std::min(best, (path[0] - xy).norm());
  }
  return best;
}

namespace {

std::vector<Crater> PlaceCraters(const WorldOptions& options, double half_m, SeededRandom& rng) {
  std::vector<Crater> craters;
  for (int k = 0; k < options.crater_count; ++k) {
    for (int attempt = 0; attempt < 200; ++attempt) {
      Crater c;
      c.radius_m =
          std::min(k == 0 ? rng.Uniform(5.0, 7.0) : rng.Uniform(2.5, 6.0), options.size_m / 8.0);
      // Depth-to-diameter about 0.1, as for small fresh craters.
      c.depth_m = c.radius_m * rng.Uniform(0.18, 0.26);
      c.rim_height_m = rng.Uniform(0.3, 0.5);
      c.scarp_drop_m = rng.Uniform(0.42, 0.55);
      c.scarp_width_m = rng.Uniform(0.15, 0.22);
      const Eigen::Vector2d direction = RandomUnitVector(rng);
      const double inner_limit = half_m - c.radius_m - 2.0;
      if (static_cast<std::size_t>(k) < options.crater_centers_xy_m.size()) {
        c.center_xy = options.crater_centers_xy_m[static_cast<std::size_t>(k)];
      } else if (k == 0) {
        // The first crater lies 15-30 m out (less in small worlds), within
        // reach of routes from the start but clear of it.
        const double d_max = std::max(std::min(28.0, inner_limit), 0.0);
        const double d_min = std::min(18.0, 0.75 * d_max);
        c.center_xy = direction * rng.Uniform(d_min, d_max);
      } else {
        c.center_xy = Eigen::Vector2d(rng.Uniform(-inner_limit, inner_limit),
                                      rng.Uniform(-inner_limit, inner_limit));
        if (c.center_xy.norm() < options.clear_radius_m + 1.5 * c.radius_m + 2.0) continue;
      }
      const bool overlaps = std::any_of(craters.begin(), craters.end(), [&](const Crater& other) {
        return (other.center_xy - c.center_xy).norm() < 1.5 * (other.radius_m + c.radius_m);
      });
      if (overlaps) continue;
      craters.push_back(c);
      break;
    }
  }
  return craters;
}

struct PostSite {
  Eigen::Vector2d xy;
  Eigen::Vector2d heading;  // unit x axis of the post frame
};

std::vector<PostSite> PlacePosts(const WorldOptions& options, double half_m,
                                 const std::vector<Crater>& craters, SeededRandom& rng) {
  std::vector<PostSite> posts;
  const double r_max = std::min(40.0, half_m - 2.0);
  const double r_min = std::min(5.0, 0.5 * r_max);
  for (int k = 0; k < options.landmark_post_count; ++k) {
    if (static_cast<std::size_t>(k) < options.landmark_posts_xy_m.size()) {
      posts.push_back(
          {options.landmark_posts_xy_m[static_cast<std::size_t>(k)], RandomUnitVector(rng)});
      continue;
    }
    for (int attempt = 0; attempt < 1000; ++attempt) {
      const Eigen::Vector2d direction = RandomUnitVector(rng);
      // Uniform over the annulus's area.
      const double r = std::sqrt(rng.Uniform(r_min * r_min, r_max * r_max));
      const Eigen::Vector2d xy = direction * r;
      const Eigen::Vector2d heading = RandomUnitVector(rng);
      if (xy.norm() < options.clear_radius_m + 1.0) continue;
      if (DistanceToClearPaths(options, xy) < options.clear_path_half_width_m + 0.5) continue;
      const bool near_crater = std::any_of(craters.begin(), craters.end(), [&](const Crater& c) {
        return (c.center_xy - xy).norm() < c.radius_m + 3.0;
      });
      const bool near_post = std::any_of(
          posts.begin(), posts.end(), [&](const PostSite& p) { return (p.xy - xy).norm() < 4.0; });
      if (near_crater || near_post) continue;
      posts.push_back({xy, heading});
      break;
    }
  }
  return posts;
}

std::vector<Rock> PlaceRocks(const WorldOptions& options, double half_m,
                             const std::vector<Crater>& craters, const std::vector<PostSite>& posts,
                             SeededRandom& rng) {
  std::vector<Rock> rocks;
  rocks.reserve(static_cast<std::size_t>(options.rock_count));
  std::vector<double> outer_radii;
  for (int k = 0; k < options.rock_count; ++k) {
    for (int attempt = 0; attempt < 30; ++attempt) {
      Rock rock;
      // Many small rocks, few large ones (heights 0.1 .. 0.6 m).
      rock.height_m = 0.1 + 0.5 * std::pow(rng.Uniform(), 2.2);
      rock.radius_m = rock.height_m * rng.Uniform(1.2, 2.0) + 0.03;
      rock.shape_exponent = rng.Uniform(2.0, 3.2);
      // Irregular outlines: lopsided (k = 1), elongated (k = 2), angular (k = 3).
      rock.outline_harmonics = {rng.Uniform(-0.06, 0.06), rng.Uniform(-0.06, 0.06),
                                rng.Uniform(-0.1, 0.1),   rng.Uniform(-0.1, 0.1),
                                rng.Uniform(-0.05, 0.05), rng.Uniform(-0.05, 0.05)};
      rock.surface_seed = rng.Bits();
      const double outer = RockOuterRadius(rock);
      // A fifth of the rocks are ejecta strewn around the craters.
      const bool ejecta = !craters.empty() && rng.Uniform() < 0.2;
      if (ejecta) {
        const Crater& c = craters[static_cast<std::size_t>(rng.Bits() % craters.size())];
        const Eigen::Vector2d direction = RandomUnitVector(rng);
        rock.center_xy =
            c.center_xy + direction * rng.Uniform(c.radius_m + 0.8 + outer, 2.2 * c.radius_m);
      } else {
        const double limit = half_m - outer - 0.5;
        rock.center_xy = Eigen::Vector2d(rng.Uniform(-limit, limit), rng.Uniform(-limit, limit));
      }
      const Eigen::Vector2d& p = rock.center_xy;
      if (std::abs(p.x()) > half_m - outer - 0.5 || std::abs(p.y()) > half_m - outer - 0.5) {
        continue;
      }
      if (p.norm() < options.clear_radius_m + outer) continue;
      if (DistanceToClearPaths(options, p) < options.clear_path_half_width_m + outer) continue;
      // Keep rocks off the crater rims, so the rim stays a clean drop.
      const bool on_rim = std::any_of(craters.begin(), craters.end(), [&](const Crater& c) {
        const double d = (c.center_xy - p).norm();
        return d > c.radius_m - c.scarp_width_m - outer - 0.3 && d < c.radius_m + outer + 0.5;
      });
      const bool near_post = std::any_of(posts.begin(), posts.end(), [&](const PostSite& post) {
        return (post.xy - p).norm() < outer + 1.0;
      });
      if (on_rim || near_post) continue;
      bool overlaps = false;
      for (std::size_t j = 0; j < rocks.size() && !overlaps; ++j) {
        overlaps = (rocks[j].center_xy - p).norm() < outer + outer_radii[j] + 0.05;
      }
      if (overlaps) continue;
      rocks.push_back(rock);
      outer_radii.push_back(outer);
      break;
    }
  }
  return rocks;
}

// Largest |gradient| over the baseline, from central differences of
// `half_baseline` samples on either side, over all interior samples.
double MaxSlope(const std::vector<float>& heights, int n, int half_baseline, double resolution_m) {
  const double inv_baseline = 1.0 / (2.0 * half_baseline * resolution_m);
  double max_squared = 0.0;
  for (int iy = half_baseline; iy < n - half_baseline; ++iy) {
    for (int ix = half_baseline; ix < n - half_baseline; ++ix) {
      const double gx = (static_cast<double>(heights[Index(ix + half_baseline, iy, n)]) -
                         static_cast<double>(heights[Index(ix - half_baseline, iy, n)])) *
                        inv_baseline;
      const double gy = (static_cast<double>(heights[Index(ix, iy + half_baseline, n)]) -
                         static_cast<double>(heights[Index(ix, iy - half_baseline, n)])) *
                        inv_baseline;
      max_squared = std::max(max_squared, gx * gx + gy * gy);
    }
  }
  return std::sqrt(max_squared);
}

// Adds f(x, y) over the samples within `radius_m` of `center`.
template <typename F>
void AddOverDisc(std::vector<float>& heights, int n, double origin_m, double resolution_m,
                 const Eigen::Vector2d& center, double radius_m, F f) {
  const auto first = [&](double v) {
    return std::clamp(static_cast<int>(std::floor((v - radius_m - origin_m) / resolution_m)), 0,
                      n - 1);
  };
  const auto last = [&](double v) {
    return std::clamp(static_cast<int>(std::ceil((v + radius_m - origin_m) / resolution_m)), 0,
                      n - 1);
  };
  for (int iy = first(center.y()); iy <= last(center.y()); ++iy) {
    const double y = origin_m + resolution_m * iy;
    for (int ix = first(center.x()); ix <= last(center.x()); ++ix) {
      const double x = origin_m + resolution_m * ix;
      float& h = heights[Index(ix, iy, n)];
      h = static_cast<float>(static_cast<double>(h) + f(x, y));
    }
  }
}

Heightfield BuildTerrain(const WorldOptions& options, uint64_t seed, int n,
                         const std::vector<Rock>& rocks, const std::vector<Crater>& craters) {
  const double res = options.resolution_m;
  const double origin = -0.5 * res * (n - 1);
  // Hills from 64 m down to 2 m; amplitude proportional to wavelength, so
  // every octave adds about the same slope (fBm with H = 1).
  const FractalNoise undulation(
      seed, kLayerUndulation,
      {{64.0, 1.0}, {32.0, 0.5}, {16.0, 0.25}, {8.0, 0.125}, {4.0, 0.0625}, {2.0, 0.03125}});
  // A few centimetres of regolith roughness, 1 m down to 12.5 cm.
  const FractalNoise roughness(seed, kLayerRoughness,
                               {{1.0, 0.03}, {0.5, 0.017}, {0.25, 0.01}, {0.125, 0.006}});
  const std::size_t count = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
  std::vector<float> hills(count);
  std::vector<float> heights(count);
  for (int iy = 0; iy < n; ++iy) {
    const double y = origin + res * iy;
    for (int ix = 0; ix < n; ++ix) {
      const double x = origin + res * ix;
      hills[Index(ix, iy, n)] = static_cast<float>(undulation.At(x, y));
      heights[Index(ix, iy, n)] = static_cast<float>(roughness.At(x, y));
    }
  }
  // Scale the hills so that hills + roughness stay below the slope limit:
  // the difference operator is linear, so max|D(s U + R)| <= s max|DU| + max|DR|.
  const int half_baseline = std::max(1, static_cast<int>(std::lround(0.5 * kSlopeBaselineM / res)));
  const double max_hill_slope = MaxSlope(hills, n, half_baseline, res);
  const double max_rough_slope = MaxSlope(heights, n, half_baseline, res);
  const double limit = std::tan((options.max_slope_deg - kSlopeMarginDeg) * kPi / 180.0);
  const double scale =
      max_hill_slope > 0.0 ? std::max(0.0, limit - max_rough_slope) / max_hill_slope : 0.0;
  for (std::size_t i = 0; i < count; ++i) {
    heights[i] =
        static_cast<float>(scale * static_cast<double>(hills[i]) + static_cast<double>(heights[i]));
  }
  hills = {};

  for (const Crater& crater : craters) {
    AddOverDisc(heights, n, origin, res, crater.center_xy, CraterOuterRadius(crater),
                [&crater](double x, double y) { return CraterProfileHeight(crater, x, y); });
  }
  for (const Rock& rock : rocks) {
    AddOverDisc(heights, n, origin, res, rock.center_xy, RockOuterRadius(rock),
                [&rock](double x, double y) { return RockBumpHeight(rock, x, y); });
  }
  // The rover starts at the origin at height 0 (the origin is rock-free, but
  // a crater's ejecta may reach it, so this comes last).
  const double offset =
      Heightfield(n, n, res, Eigen::Vector2d(origin, origin), heights).HeightAt(0.0, 0.0);
  for (float& h : heights) h = static_cast<float>(static_cast<double>(h) - offset);
  return Heightfield(n, n, res, Eigen::Vector2d(origin, origin), std::move(heights));
}

std::string OtherRoverName(int index) {
  // "rover_a" is the simulated rover itself.
  if (index < 25) return std::string("rover_") + static_cast<char>('b' + index);
  return "rover_" + std::to_string(index);
}

}  // namespace

double RockOuterRadius(const Rock& rock) {
  double sum = 0.0;
  for (double a : rock.outline_harmonics) sum += std::abs(a);
  return rock.radius_m * (1.0 + sum);
}

double RockBumpHeight(const Rock& rock, double x_m, double y_m) {
  const double dx = x_m - rock.center_xy.x();
  const double dy = y_m - rock.center_xy.y();
  const double d2 = dx * dx + dy * dy;
  const double outer = RockOuterRadius(rock);
  if (d2 >= outer * outer) return 0.0;
  if (d2 == 0.0) return rock.height_m;
  const double d = std::sqrt(d2);
  const double ux = dx / d;
  const double uy = dy / d;
  const auto& a = rock.outline_harmonics;
  // cos k theta, sin k theta from the direction, without trigonometry.
  const double cos2 = ux * ux - uy * uy;
  const double sin2 = 2.0 * ux * uy;
  const double cos3 = ux * cos2 - uy * sin2;
  const double sin3 = uy * cos2 + ux * sin2;
  const double r = rock.radius_m * (1.0 + a[0] * ux + a[1] * uy + a[2] * cos2 + a[3] * sin2 +
                                    a[4] * cos3 + a[5] * sin3);
  const double rho = d / r;
  if (rho >= 1.0) return 0.0;
  // Superellipsoid cross-section: steep flanks, rounded top.
  const double p = rock.shape_exponent;
  const double profile = std::pow(1.0 - std::pow(rho, p), 1.0 / p);
  // Lumps scaled to the rock (a few per rock, whatever its size) plus cm
  // grain. With |texture| <= 1 the factor profile * (1 + 0.45 texture
  // (1 - profile)) stays within [0, 1] and is 1 only at the centre, so the
  // bump stays within [0, height_m] and peaks at exactly height_m.
  const double lump = 1.0 / (0.6 * rock.radius_m);
  const double texture =
      std::clamp(1.4 * (0.75 * GradientNoise2(dx * lump, dy * lump, rock.surface_seed) +
                        0.25 * GradientNoise2(dx / 0.05, dy / 0.05, rock.surface_seed + 1)),
                 -1.0, 1.0);
  return rock.height_m * profile * (1.0 + 0.45 * texture * (1.0 - profile));
}

double CraterOuterRadius(const Crater& crater) { return 2.5 * crater.radius_m; }

double CraterProfileHeight(const Crater& crater, double x_m, double y_m) {
  const double d = (Eigen::Vector2d(x_m, y_m) - crater.center_xy).norm();
  const double rim = crater.radius_m;
  if (d >= rim) {
    // Ejecta blanket: falls from the crest to nothing at 2.5 radii.
    return crater.rim_height_m * (1.0 - SmoothStep(rim, CraterOuterRadius(crater), d));
  }
  const double inward = rim - d;
  if (inward < crater.scarp_width_m) {
    return crater.rim_height_m -
           crater.scarp_drop_m * SmoothStep(0.0, crater.scarp_width_m, inward);
  }
  const double q = d / (rim - crater.scarp_width_m);
  const double scarp_foot = crater.rim_height_m - crater.scarp_drop_m;
  return -crater.depth_m + (crater.depth_m + scarp_foot) * q * q;
}

World World::Generate(const WorldOptions& options, uint64_t seed) {
  Validate(options);
  World world;
  world.options = options;
  world.seed = seed;
  const int n = SamplesPerSide(options.size_m, options.resolution_m);
  const double half_m = 0.5 * options.resolution_m * (n - 1);

  // Placement first (one random stream, fixed order), then the heights.
  SeededRandom rng(HashCombine(seed, kLayerPlacement));
  world.craters = PlaceCraters(options, half_m, rng);
  const std::vector<PostSite> posts = PlacePosts(options, half_m, world.craters, rng);
  world.rocks = PlaceRocks(options, half_m, world.craters, posts, rng);
  world.terrain = BuildTerrain(options, seed, n, world.rocks, world.craters);

  int next_tag_id = 0;
  for (std::size_t k = 0; k < posts.size(); ++k) {
    const PostSite& site = posts[k];
    Eigen::Isometry3d T_world_carrier = Eigen::Isometry3d::Identity();
    T_world_carrier.linear() << site.heading.x(), -site.heading.y(), 0.0,  //
        site.heading.y(), site.heading.x(), 0.0,                           //
        0.0, 0.0, 1.0;
    T_world_carrier.translation() =
        Eigen::Vector3d(site.xy.x(), site.xy.y(), world.terrain.HeightAt(site.xy.x(), site.xy.y()));
    world.carriers.push_back(MakeLandmarkPost("post_" + std::to_string(k), next_tag_id,
                                              options.tag_size_m, T_world_carrier));
    next_tag_id += 4;
  }
  for (int k = 0; k < options.other_rover_count; ++k) {
    world.carriers.push_back(
        MakeOtherRover(OtherRoverName(k), next_tag_id, options.rover_tag_size_m));
    next_tag_id += 5;
  }
  if (options.recording_rover_carries_tags) {
    world.carriers.push_back(MakeOtherRover("rover_a", next_tag_id, options.rover_tag_size_m));
    next_tag_id += 5;
  }

  world.albedo = GenerateAlbedo(options, seed, world.rocks, world.craters);
  return world;
}

}  // namespace rover::sim
