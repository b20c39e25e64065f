#include "mapping/submap/submap_options.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace rover::mapping {
namespace {

[[noreturn]] void Fail(const char* key, const char* expected, double got) {
  throw std::invalid_argument(std::string("SubmapOptions.") + key + ": expected " + expected +
                              ", got " + std::to_string(got));
}

[[noreturn]] void Fail(const char* key, const char* expected, int got) {
  throw std::invalid_argument(std::string("SubmapOptions.") + key + ": expected " + expected +
                              ", got " + std::to_string(got));
}

}  // namespace

void SubmapOptions::Validate() const {
  // Below 1 mm OctoMap's 16-bit keys would cover less than +-33 m.
  if (!(std::isfinite(octree_resolution_m) && octree_resolution_m >= 0.001)) {
    Fail("octree_resolution_m", ">= 0.001", octree_resolution_m);
  }
  // A hit must raise and a miss lower the occupancy, or the map cannot
  // tell surfaces from free space.
  if (!(prob_hit > 0.5 && prob_hit < 1.0)) Fail("prob_hit", "in (0.5, 1)", prob_hit);
  if (!(prob_miss > 0.0 && prob_miss < 0.5)) Fail("prob_miss", "in (0, 0.5)", prob_miss);
  if (!(clamping_min > 0.0 && clamping_min < 0.5)) {
    Fail("clamping_min", "in (0, 0.5)", clamping_min);
  }
  if (!(clamping_max > 0.5 && clamping_max < 1.0)) {
    Fail("clamping_max", "in (0.5, 1)", clamping_max);
  }
  if (!(std::isfinite(cloud_resolution_m) && cloud_resolution_m >= 0.001)) {
    Fail("cloud_resolution_m", ">= 0.001", cloud_resolution_m);
  }
  if (!(std::isfinite(max_free_range_m) && max_free_range_m >= 0.0)) {
    Fail("max_free_range_m", ">= 0 (0: off)", max_free_range_m);
  }
  if (ray_cells_per_voxel_edge < 1 || ray_cells_per_voxel_edge > 4) {
    Fail("ray_cells_per_voxel_edge", "1..4", ray_cells_per_voxel_edge);
  }
  if (!(std::isfinite(max_range_m) && max_range_m >= 0.0)) {
    Fail("max_range_m", ">= 0 (0: unlimited)", max_range_m);
  }
}

}  // namespace rover::mapping
