// Obstacle ground truth: the rule documented at ComputeObstacleCells, on the
// heightfield's own grid.

#include <algorithm>
#include <charconv>
#include <cmath>
#include <string>
#include <vector>

#include "hil/sim/world/world.h"

namespace rover::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Half-width of a square window of `window_m`, in whole cells (at least 1).
int HalfWindowCells(double window_m, double resolution_m) {
  return std::max(1, static_cast<int>(std::lround(0.5 * window_m / resolution_m)));
}

std::size_t Index(int ix, int iy, int cols) {
  return static_cast<std::size_t>(iy) * static_cast<std::size_t>(cols) +
         static_cast<std::size_t>(ix);
}

// Minimum over the (2k+1)^2 window around each sample, clipped at the border;
// separable (rows, then columns).
std::vector<float> WindowMinimum(const Heightfield& terrain, int k) {
  const int cols = terrain.cols();
  const int rows = terrain.rows();
  const std::vector<float>& h = terrain.heights_m();
  std::vector<float> along_x(h.size());
  for (int iy = 0; iy < rows; ++iy) {
    for (int ix = 0; ix < cols; ++ix) {
      float m = h[Index(ix, iy, cols)];
      for (int j = std::max(0, ix - k); j <= std::min(cols - 1, ix + k); ++j) {
        m = std::min(m, h[Index(j, iy, cols)]);
      }
      along_x[Index(ix, iy, cols)] = m;
    }
  }
  std::vector<float> result(h.size());
  for (int iy = 0; iy < rows; ++iy) {
    for (int ix = 0; ix < cols; ++ix) {
      float m = along_x[Index(ix, iy, cols)];
      for (int j = std::max(0, iy - k); j <= std::min(rows - 1, iy + k); ++j) {
        m = std::min(m, along_x[Index(ix, j, cols)]);
      }
      result[Index(ix, iy, cols)] = m;
    }
  }
  return result;
}

}  // namespace

ObstacleGrid ComputeObstacleCells(const World& world, const ObstacleRuleOptions& rule) {
  const Heightfield& terrain = world.terrain;
  ObstacleGrid grid;
  grid.cols = terrain.cols();
  grid.rows = terrain.rows();
  grid.resolution_m = terrain.resolution_m();
  grid.origin_xy = terrain.origin_xy();
  const int cols = grid.cols;
  const int rows = grid.rows;
  grid.codes.assign(static_cast<std::size_t>(cols) * static_cast<std::size_t>(rows),
                    static_cast<uint8_t>(ObstacleCode::kFree));
  if (cols < 2 || rows < 2) return grid;
  const double res = grid.resolution_m;
  const double ox = grid.origin_xy.x();
  const double oy = grid.origin_xy.y();

  // 1. Rocks, whole: the ground truth knows which samples they cover.
  const auto to_cell = [res](double v, double origin, int count, bool up) {
    const double u = (v - origin) / res;
    return std::clamp(static_cast<int>(up ? std::ceil(u) : std::floor(u)), 0, count - 1);
  };
  for (const Rock& rock : world.rocks) {
    const double outer = RockOuterRadius(rock);
    for (int iy = to_cell(rock.center_xy.y() - outer, oy, rows, false);
         iy <= to_cell(rock.center_xy.y() + outer, oy, rows, true); ++iy) {
      for (int ix = to_cell(rock.center_xy.x() - outer, ox, cols, false);
           ix <= to_cell(rock.center_xy.x() + outer, ox, cols, true); ++ix) {
        if (RockBumpHeight(rock, ox + res * ix, oy + res * iy) > rule.rock_min_height_m) {
          grid.codes[Index(ix, iy, cols)] = static_cast<uint8_t>(ObstacleCode::kPositive);
        }
      }
    }
  }

  const std::vector<float>& h = terrain.heights_m();
  const int k_negative = HalfWindowCells(rule.negative_window_m, res);
  const int k_slope = HalfWindowCells(rule.slope_window_m, res);
  const int k_step = HalfWindowCells(rule.step_window_m, res);
  const std::vector<float> window_min = WindowMinimum(terrain, k_negative);
  const double max_gradient = std::tan(rule.max_slope_deg * kPi / 180.0);

  // Least-squares plane over the (2k+1)^2 slope window on a regular grid:
  // dz/dx = sum(i h) / (res * (2k+1) * sum(i^2)), likewise for y. Border
  // samples are replicated outward so every window is full.
  const double sum_i2 = k_slope * (k_slope + 1) * (2.0 * k_slope + 1) / 3.0;
  const double gradient_norm = 1.0 / (res * (2.0 * k_slope + 1.0) * sum_i2);
  const auto height = [&](int ix, int iy) {
    return static_cast<double>(
        h[Index(std::clamp(ix, 0, cols - 1), std::clamp(iy, 0, rows - 1), cols)]);
  };
  std::vector<double> column_sum(static_cast<std::size_t>(cols));
  std::vector<double> column_moment(static_cast<std::size_t>(cols));
  for (int iy = 0; iy < rows; ++iy) {
    for (int ix = 0; ix < cols; ++ix) {
      double sum = 0.0;
      double moment = 0.0;
      for (int j = -k_slope; j <= k_slope; ++j) {
        const double v = height(ix, iy + j);
        sum += v;
        moment += j * v;
      }
      column_sum[static_cast<std::size_t>(ix)] = sum;
      column_moment[static_cast<std::size_t>(ix)] = moment;
    }
    for (int ix = 0; ix < cols; ++ix) {
      uint8_t& code = grid.codes[Index(ix, iy, cols)];
      if (code != static_cast<uint8_t>(ObstacleCode::kFree)) continue;
      const double center = static_cast<double>(h[Index(ix, iy, cols)]);
      // 2. Top edge of a drop.
      if (center - static_cast<double>(window_min[Index(ix, iy, cols)]) > rule.negative_drop_m) {
        code = static_cast<uint8_t>(ObstacleCode::kNegative);
        continue;
      }
      double gx = 0.0;
      double gy = 0.0;
      for (int i = -k_slope; i <= k_slope; ++i) {
        const auto c = static_cast<std::size_t>(std::clamp(ix + i, 0, cols - 1));
        gx += i * column_sum[c];
        gy += column_moment[c];
      }
      gx *= gradient_norm;
      gy *= gradient_norm;
      // 3. A step: the height range left after removing the plane.
      double low = 0.0;
      double high = 0.0;
      for (int j = std::max(0, iy - k_step); j <= std::min(rows - 1, iy + k_step); ++j) {
        for (int i = std::max(0, ix - k_step); i <= std::min(cols - 1, ix + k_step); ++i) {
          const double residual = static_cast<double>(h[Index(i, j, cols)]) - center -
                                  res * (gx * (i - ix) + gy * (j - iy));
          low = std::min(low, residual);
          high = std::max(high, residual);
        }
      }
      if (high - low > rule.step_height_m) {
        code = static_cast<uint8_t>(ObstacleCode::kPositive);
      } else if (gx * gx + gy * gy > max_gradient * max_gradient) {
        // 4. Too steep.
        code = static_cast<uint8_t>(ObstacleCode::kSlope);
      }
    }
  }
  return grid;
}

std::string DescribeObstacleRule(const ObstacleRuleOptions& rule) {
  // Shortest round-trip form; unlike std::to_string it ignores the locale.
  const auto num = [](double v) {
    char buffer[32];
    const auto result = std::to_chars(buffer, buffer + sizeof(buffer), v);
    return std::string(buffer, result.ptr);
  };
  std::string text;
  text += "Each heightfield sample is classified; the first rule that applies sets its code.\n";
  text += "Windows are squares centred on the sample, half-width rounded to whole cells.\n";
  text += "1 positive: a rock adds more than " + num(rule.rock_min_height_m) +
          " m to the ground here (rocks count whole, flat tops included).\n";
  text += "3 negative: within a " + num(rule.negative_window_m) +
          " m window some terrain lies more than " + num(rule.negative_drop_m) +
          " m below this sample (the top edge of a drop: crater scarp, cliff).\n";
  text += "1 positive: after removing the least-squares plane fitted over a " +
          num(rule.slope_window_m) + " m window, the heights within a " + num(rule.step_window_m) +
          " m window span more than " + num(rule.step_height_m) +
          " m (a step a wheel cannot climb).\n";
  text += "2 slope: that plane is steeper than " + num(rule.max_slope_deg) + " degrees.\n";
  text += "0 free: none of the above.\n";
  return text;
}

}  // namespace rover::sim
