// The albedo texture. Fields with features of 0.5 m and more are evaluated on
// a grid 4x coarser and interpolated; pebbles and grain are evaluated per
// sample. Rocks and craters are painted row by row, so no full-size float
// buffer is needed.

#include "hil/sim/world/albedo.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "hil/sim/world/noise.h"

namespace rover::sim {
namespace {

constexpr uint64_t kLayerPatches = 10;
constexpr uint64_t kLayerDarkBlotches = 11;
constexpr uint64_t kLayerLightBlotches = 12;
constexpr uint64_t kLayerPebbleTone = 13;
constexpr uint64_t kLayerGrain = 14;
constexpr uint64_t kLayerPebbles = 15;
constexpr uint64_t kLayerGrit = 16;
constexpr uint64_t kLayerWhite = 17;
constexpr uint64_t kLayerEjectaRays = 18;

constexpr int kCoarseFactor = 4;
constexpr double kMeanAlbedo = 0.45;

// Albedo of the bare regolith from the fields that vary over 0.5 m and more.
struct CoarseFields {
  FractalNoise patches;
  FractalNoise dark_blotches;
  FractalNoise light_blotches;
  FractalNoise pebble_tone;
};

// Albedo of a rock at local offset (dx, dy) from its centre: a per-rock tone,
// darker than the regolith, speckled at 4-10 cm.
double RockAlbedo(const Rock& rock, double dx, double dy) {
  const double tone = 0.22 + 0.2 * BitsToUnit(MixBits(rock.surface_seed + 7));
  return tone + 0.06 * GradientNoise2(dx / 0.1, dy / 0.1, rock.surface_seed + 8) +
         0.05 * GradientNoise2(dx / 0.04, dy / 0.04, rock.surface_seed + 9);
}

}  // namespace

AlbedoMap GenerateAlbedo(const WorldOptions& options, uint64_t seed, const std::vector<Rock>& rocks,
                         const std::vector<Crater>& craters) {
  AlbedoMap map;
  const double res = options.albedo_resolution_m;
  const int n = static_cast<int>(std::lround(options.size_m / res)) + 1;
  const double origin = -0.5 * res * (n - 1);
  map.cols = n;
  map.rows = n;
  map.resolution_m = res;
  map.origin_xy = Eigen::Vector2d(origin, origin);
  map.values.resize(static_cast<std::size_t>(n) * static_cast<std::size_t>(n));

  // Lighter and darker regolith patches, 5-40 m; blotches 0.5-2 m.
  const CoarseFields fields{
      FractalNoise(seed, kLayerPatches, {{40.0, 1.0}, {20.0, 0.5}, {10.0, 0.25}, {5.0, 0.125}}),
      FractalNoise(seed, kLayerDarkBlotches, {{2.0, 1.0}, {1.0, 0.5}, {0.5, 0.25}}),
      FractalNoise(seed, kLayerLightBlotches, {{2.0, 1.0}, {1.0, 0.5}, {0.5, 0.25}}),
      FractalNoise(seed, kLayerPebbleTone, {{0.4, 1.0}}),
  };
  const FractalNoise grain(seed, kLayerGrain, {{0.08, 1.0}});
  const FractalNoise pebbles(seed, kLayerPebbles, {{0.16, 1.0}});
  const FractalNoise grit(seed, kLayerGrit, {{0.07, 1.0}});
  const uint64_t white_salt = HashCombine(seed, kLayerWhite);
  const uint64_t ray_salt = HashCombine(seed, kLayerEjectaRays);

  // Coarse grid: base albedo and pebble tone, one sample beyond the last fine one.
  const double coarse_res = kCoarseFactor * res;
  const int nc = (n - 1) / kCoarseFactor + 2;
  std::vector<float> coarse_base(static_cast<std::size_t>(nc) * static_cast<std::size_t>(nc));
  std::vector<float> coarse_tone(coarse_base.size());
  for (int jy = 0; jy < nc; ++jy) {
    const double y = origin + coarse_res * jy;
    for (int jx = 0; jx < nc; ++jx) {
      const double x = origin + coarse_res * jx;
      // tanh sharpens the patch borders a little: regolith tones change over
      // metres, not smoothly over the whole patch.
      const double patches = 0.09 * std::tanh(2.0 * fields.patches.At(x, y));
      const double dark = -0.09 * SmoothStep(0.22, 0.36, fields.dark_blotches.At(x, y));
      const double light = 0.07 * SmoothStep(0.28, 0.42, fields.light_blotches.At(x, y));
      const std::size_t i = static_cast<std::size_t>(jy) * static_cast<std::size_t>(nc) +
                            static_cast<std::size_t>(jx);
      coarse_base[i] = static_cast<float>(kMeanAlbedo + patches + dark + light);
      coarse_tone[i] = static_cast<float>(std::clamp(3.0 * fields.pebble_tone.At(x, y), -1.0, 1.0));
    }
  }

  std::vector<double> row(static_cast<std::size_t>(n));
  std::vector<const Rock*> row_rocks;
  for (int iy = 0; iy < n; ++iy) {
    const double y = origin + res * iy;
    const int jy = iy / kCoarseFactor;
    const double wy = static_cast<double>(iy % kCoarseFactor) / kCoarseFactor;
    const auto coarse = [&](const std::vector<float>& field, int ix) {
      const int jx = ix / kCoarseFactor;
      const double wx = static_cast<double>(ix % kCoarseFactor) / kCoarseFactor;
      const auto at = [&](int cx, int cy) {
        return static_cast<double>(
            field[static_cast<std::size_t>(cy) * static_cast<std::size_t>(nc) +
                  static_cast<std::size_t>(cx)]);
      };
      const double bottom = at(jx, jy) + wx * (at(jx + 1, jy) - at(jx, jy));
      const double top = at(jx, jy + 1) + wx * (at(jx + 1, jy + 1) - at(jx, jy + 1));
      return bottom + wy * (top - bottom);
    };
    for (int ix = 0; ix < n; ++ix) {
      const double x = origin + res * ix;
      double a = coarse(coarse_base, ix);
      // Grain: smooth 8 cm noise plus per-sample speckle.
      a += 0.035 * grain.At(x, y) + 0.02 * BitsToSigned(LatticeHash(ix, iy, white_salt));
      // Pebbles of a few cm, lighter or darker by the local tone, with sharp
      // edges (corners for feature detectors at close range).
      a += 0.16 * coarse(coarse_tone, ix) * SmoothStep(0.27, 0.34, pebbles.At(x, y));
      a -= 0.08 * SmoothStep(0.33, 0.40, grit.At(x, y));
      row[static_cast<std::size_t>(ix)] = a;
    }

    const auto column_range = [&](double center_x, double radius_m, int* first, int* last) {
      *first =
          std::clamp(static_cast<int>(std::floor((center_x - radius_m - origin) / res)), 0, n - 1);
      *last =
          std::clamp(static_cast<int>(std::ceil((center_x + radius_m - origin) / res)), 0, n - 1);
    };
    for (const Crater& crater : craters) {
      const double outer = 2.2 * crater.radius_m;
      const double dy = y - crater.center_xy.y();
      if (std::abs(dy) >= outer) continue;
      int first = 0;
      int last = 0;
      column_range(crater.center_xy.x(), outer, &first, &last);
      for (int ix = first; ix <= last; ++ix) {
        const double dx = origin + res * ix - crater.center_xy.x();
        const double d = std::sqrt(dx * dx + dy * dy);
        double& a = row[static_cast<std::size_t>(ix)];
        if (d < crater.radius_m) {
          // Darker, finer material inside; the scarp exposes fresher, lighter rock.
          const double inward = crater.radius_m - d;
          a *= 1.0 - 0.12 * SmoothStep(0.0, 1.5, inward);
          a += 0.06 * (1.0 - SmoothStep(crater.scarp_width_m, crater.scarp_width_m + 0.3, inward));
        } else if (d < outer && d > 0.0) {
          // Bright ejecta in radial rays: noise of the direction only.
          const double ray = std::clamp(
              1.4 * GradientNoise2(3.0 * dx / d + 50.0, 3.0 * dy / d + 50.0, ray_salt), -1.0, 1.0);
          a += 0.07 * (1.0 - SmoothStep(crater.radius_m, outer, d)) * (0.6 + 0.4 * ray);
        }
      }
    }

    row_rocks.clear();
    for (const Rock& rock : rocks) {
      if (std::abs(y - rock.center_xy.y()) < RockOuterRadius(rock)) row_rocks.push_back(&rock);
    }
    for (const Rock* rock : row_rocks) {
      int first = 0;
      int last = 0;
      column_range(rock->center_xy.x(), RockOuterRadius(*rock), &first, &last);
      for (int ix = first; ix <= last; ++ix) {
        const double x = origin + res * ix;
        const double bump = RockBumpHeight(*rock, x, y);
        if (bump <= 0.0) continue;
        // Fully rock-coloured once the rock stands 1.5 cm proud of the ground.
        const double w = SmoothStep(0.0, 0.015, bump);
        double& a = row[static_cast<std::size_t>(ix)];
        a += w * (RockAlbedo(*rock, x - rock->center_xy.x(), y - rock->center_xy.y()) - a);
      }
    }

    uint8_t* out = map.values.data() + static_cast<std::size_t>(iy) * static_cast<std::size_t>(n);
    for (int ix = 0; ix < n; ++ix) {
      const double a = std::clamp(row[static_cast<std::size_t>(ix)], 0.03, 0.97);
      out[ix] = static_cast<uint8_t>(std::lround(a * 255.0));
    }
  }
  return map;
}

}  // namespace rover::sim
