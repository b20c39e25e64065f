#include "hil/sim/render/terrain_lod.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace rover::sim {
namespace {

std::size_t Index(int x, int y, int nx) {
  return static_cast<std::size_t>(y) * static_cast<std::size_t>(nx) + static_cast<std::size_t>(x);
}

}  // namespace

TerrainQuadtree::TerrainQuadtree(const Heightfield& terrain)
    : cols_(terrain.cols()),
      rows_(terrain.rows()),
      resolution_m_(terrain.resolution_m()),
      origin_xy_(terrain.origin_xy()) {
  if (cols_ < 2 || rows_ < 2) throw std::invalid_argument("TerrainQuadtree: empty heightfield");
  // Level 0: bounds over the (kPatchQuads + 1)^2 samples of each patch,
  // including the shared border samples.
  Level level0;
  level0.nx = (cols_ - 1 + kPatchQuads - 1) / kPatchQuads;
  level0.ny = (rows_ - 1 + kPatchQuads - 1) / kPatchQuads;
  const std::size_t count0 =
      static_cast<std::size_t>(level0.nx) * static_cast<std::size_t>(level0.ny);
  level0.z_min.assign(count0, std::numeric_limits<float>::max());
  level0.z_max.assign(count0, std::numeric_limits<float>::lowest());
  level0.error_m.assign(count0, 0.0f);  // level 0 is the full-resolution mesh
  for (int iy = 0; iy < rows_; ++iy) {
    // A sample on a patch border belongs to both patches.
    const int py_lo = (iy % kPatchQuads == 0 && iy > 0) ? iy / kPatchQuads - 1 : iy / kPatchQuads;
    const int py_hi = std::min(iy / kPatchQuads, level0.ny - 1);
    for (int ix = 0; ix < cols_; ++ix) {
      const float z = terrain.HeightAtCell(ix, iy);
      const int px_lo = (ix % kPatchQuads == 0 && ix > 0) ? ix / kPatchQuads - 1 : ix / kPatchQuads;
      const int px_hi = std::min(ix / kPatchQuads, level0.nx - 1);
      for (int py = py_lo; py <= py_hi; ++py) {
        for (int px = px_lo; px <= px_hi; ++px) {
          const std::size_t i = Index(px, py, level0.nx);
          level0.z_min[i] = std::min(level0.z_min[i], z);
          level0.z_max[i] = std::max(level0.z_max[i], z);
        }
      }
    }
  }
  levels_.push_back(std::move(level0));
  while (levels_.back().nx > 1 || levels_.back().ny > 1) {
    const Level& fine = levels_.back();
    Level coarse;
    coarse.nx = (fine.nx + 1) / 2;
    coarse.ny = (fine.ny + 1) / 2;
    const std::size_t count =
        static_cast<std::size_t>(coarse.nx) * static_cast<std::size_t>(coarse.ny);
    coarse.z_min.assign(count, std::numeric_limits<float>::max());
    coarse.z_max.assign(count, std::numeric_limits<float>::lowest());
    coarse.error_m.assign(count, 0.0f);
    for (int y = 0; y < fine.ny; ++y) {
      for (int x = 0; x < fine.nx; ++x) {
        const std::size_t c = Index(x / 2, y / 2, coarse.nx);
        const std::size_t f = Index(x, y, fine.nx);
        coarse.z_min[c] = std::min(coarse.z_min[c], fine.z_min[f]);
        coarse.z_max[c] = std::max(coarse.z_max[c], fine.z_max[f]);
        // A patch is never finer than its children: refining must not make
        // the error grow.
        coarse.error_m[c] = std::max(coarse.error_m[c], fine.error_m[f]);
      }
    }
    levels_.push_back(std::move(coarse));
    ComputeErrors(terrain, levels() - 1);
  }
}

void TerrainQuadtree::ComputeErrors(const Heightfield& terrain, int level) {
  // Largest difference between each full-resolution sample and the level's
  // mesh, triangulated as drawn (diagonal from the cell's (0, 0) to (1, 1)).
  Level& l = levels_[static_cast<std::size_t>(level)];
  const int stride = 1 << level;
  const int span = kPatchQuads * stride;
  for (int iy = 0; iy < rows_; ++iy) {
    const int y0 = std::min((iy / stride) * stride, rows_ - 1);
    const int y1 = std::min(y0 + stride, rows_ - 1);
    const float fy = y1 > y0 ? static_cast<float>(iy - y0) / static_cast<float>(y1 - y0) : 0.0f;
    const int py = std::min(iy / span, l.ny - 1);
    for (int ix = 0; ix < cols_; ++ix) {
      const int x0 = std::min((ix / stride) * stride, cols_ - 1);
      const int x1 = std::min(x0 + stride, cols_ - 1);
      const float fx = x1 > x0 ? static_cast<float>(ix - x0) / static_cast<float>(x1 - x0) : 0.0f;
      const float h00 = terrain.HeightAtCell(x0, y0);
      const float h11 = terrain.HeightAtCell(x1, y1);
      const float h = fx >= fy ? h00 + fx * (terrain.HeightAtCell(x1, y0) - h00) +
                                     fy * (h11 - terrain.HeightAtCell(x1, y0))
                               : h00 + fy * (terrain.HeightAtCell(x0, y1) - h00) +
                                     fx * (h11 - terrain.HeightAtCell(x0, y1));
      const int px = std::min(ix / span, l.nx - 1);
      float& error = l.error_m[Index(px, py, l.nx)];
      error = std::max(error, std::abs(terrain.HeightAtCell(ix, iy) - h));
    }
  }
}

TerrainPatch TerrainQuadtree::MakePatch(int level, int px, int py,
                                        const Eigen::Vector3d& eye) const {
  TerrainPatch patch;
  patch.level = level;
  patch.stride_cells = 1 << level;
  const int span = kPatchQuads * patch.stride_cells;
  patch.ix0 = px * span;
  patch.iy0 = py * span;
  const int ix1 = std::min(patch.ix0 + span, cols_ - 1);
  const int iy1 = std::min(patch.iy0 + span, rows_ - 1);
  const Level& l = levels_[static_cast<std::size_t>(level)];
  const std::size_t i = Index(px, py, l.nx);
  patch.min_world = Eigen::Vector3d(origin_xy_.x() + resolution_m_ * patch.ix0,
                                    origin_xy_.y() + resolution_m_ * patch.iy0, l.z_min[i]);
  patch.max_world = Eigen::Vector3d(origin_xy_.x() + resolution_m_ * ix1,
                                    origin_xy_.y() + resolution_m_ * iy1, l.z_max[i]);
  const Eigen::Vector3d nearest = eye.cwiseMax(patch.min_world).cwiseMin(patch.max_world);
  patch.distance_m = (eye - nearest).norm();
  patch.error_m = l.error_m[i];
  patch.edge_stride_cells = {patch.stride_cells, patch.stride_cells, patch.stride_cells,
                             patch.stride_cells};
  return patch;
}

void TerrainQuadtree::SelectRecursive(int level, int px, int py, const Eigen::Vector3d& eye,
                                      const TerrainLodParams& params,
                                      std::vector<TerrainPatch>* out) const {
  TerrainPatch patch = MakePatch(level, px, py, eye);
  const bool split =
      level > 0 && (patch.distance_m < params.full_resolution_distance_m ||
                    params.focal_px * patch.error_m > params.max_error_px * patch.distance_m);
  if (!split) {
    out->push_back(patch);
    return;
  }
  const Level& fine = levels_[static_cast<std::size_t>(level - 1)];
  for (int cy = 2 * py; cy < std::min(2 * py + 2, fine.ny); ++cy) {
    for (int cx = 2 * px; cx < std::min(2 * px + 2, fine.nx); ++cx) {
      SelectRecursive(level - 1, cx, cy, eye, params, out);
    }
  }
}

std::vector<TerrainPatch> TerrainQuadtree::Select(const Eigen::Vector3d& eye_world,
                                                  const TerrainLodParams& params) const {
  std::vector<TerrainPatch> patches;
  SelectRecursive(levels() - 1, 0, 0, eye_world, params, &patches);

  // Level of the patch covering each finest-level slot, to find coarser
  // neighbours. A coarser neighbour spans a whole edge, so probing the slot
  // next to the edge's first slot is enough.
  const Level& l0 = levels_.front();
  std::vector<int8_t> level_at(static_cast<std::size_t>(l0.nx) * static_cast<std::size_t>(l0.ny),
                               0);
  for (const TerrainPatch& p : patches) {
    const int n = 1 << p.level;
    const int sx = p.ix0 / kPatchQuads;
    const int sy = p.iy0 / kPatchQuads;
    for (int y = sy; y < std::min(sy + n, l0.ny); ++y) {
      for (int x = sx; x < std::min(sx + n, l0.nx); ++x) {
        level_at[Index(x, y, l0.nx)] = static_cast<int8_t>(p.level);
      }
    }
  }
  for (TerrainPatch& p : patches) {
    const int n = 1 << p.level;
    const int sx = p.ix0 / kPatchQuads;
    const int sy = p.iy0 / kPatchQuads;
    const std::array<std::array<int, 2>, 4> probes = {
        {{sx - 1, sy}, {sx + n, sy}, {sx, sy - 1}, {sx, sy + n}}};
    for (std::size_t e = 0; e < 4; ++e) {
      const int x = probes[e][0];
      const int y = probes[e][1];
      if (x < 0 || y < 0 || x >= l0.nx || y >= l0.ny) continue;
      const int neighbour_level = level_at[Index(x, y, l0.nx)];
      p.edge_stride_cells[e] = 1 << std::max(p.level, neighbour_level);
    }
  }
  std::sort(patches.begin(), patches.end(), [](const TerrainPatch& a, const TerrainPatch& b) {
    return a.distance_m < b.distance_m;
  });
  return patches;
}

}  // namespace rover::sim
