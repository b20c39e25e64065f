// Heightfield queries and the albedo lookup: bilinear interpolation, the
// piecewise gradient and the exact cell-by-cell ray cast.

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include "hil/sim/world/world.h"

namespace rover::sim {
namespace {

// Splits a coordinate into a cell index in [0, count - 2] and the fraction in
// [0, 1] inside it, clamping to the grid. `clamped` reports whether the point
// was outside.
struct CellCoordinate {
  int index = 0;
  double fraction = 0.0;
  bool clamped = false;
};

CellCoordinate LocateClamped(double value_m, double origin_m, double resolution_m, int count) {
  CellCoordinate c;
  const double u = (value_m - origin_m) / resolution_m;
  const double last = static_cast<double>(count - 1);
  if (!(u > 0.0)) {  // also catches NaN
    c.clamped = u < 0.0;
    return c;
  }
  if (u >= last) {
    c.index = count - 2;
    c.fraction = 1.0;
    c.clamped = u > last;
    return c;
  }
  const double cell = std::floor(u);
  c.index = std::min(static_cast<int>(cell), count - 2);
  c.fraction = u - static_cast<double>(c.index);
  return c;
}

}  // namespace

Heightfield::Heightfield(int cols, int rows, double resolution_m, Eigen::Vector2d origin_xy,
                         std::vector<float> heights_m)
    : cols_(cols),
      rows_(rows),
      resolution_m_(resolution_m),
      origin_xy_(std::move(origin_xy)),
      heights_m_(std::move(heights_m)) {
  if (cols_ < 2 || rows_ < 2 || !(resolution_m_ > 0.0) ||
      heights_m_.size() != static_cast<std::size_t>(cols_) * static_cast<std::size_t>(rows_)) {
    throw std::invalid_argument(
        "Heightfield: need >= 2 x 2 samples, cols * rows heights and a "
        "positive resolution");
  }
  const auto [lowest, highest] = std::minmax_element(heights_m_.begin(), heights_m_.end());
  min_height_m_ = *lowest;
  max_height_m_ = *highest;
}

Eigen::Vector2d Heightfield::max_xy() const {
  return origin_xy_ + resolution_m_ * Eigen::Vector2d(cols_ - 1, rows_ - 1);
}

bool Heightfield::Contains(double x_m, double y_m) const {
  if (cols_ < 2 || rows_ < 2) return false;
  const Eigen::Vector2d last = max_xy();
  return x_m >= origin_xy_.x() && x_m <= last.x() && y_m >= origin_xy_.y() && y_m <= last.y();
}

double Heightfield::HeightAt(double x_m, double y_m) const {
  if (cols_ < 2 || rows_ < 2) return 0.0;
  const CellCoordinate cx = LocateClamped(x_m, origin_xy_.x(), resolution_m_, cols_);
  const CellCoordinate cy = LocateClamped(y_m, origin_xy_.y(), resolution_m_, rows_);
  const double h00 = HeightAtCell(cx.index, cy.index);
  const double h10 = HeightAtCell(cx.index + 1, cy.index);
  const double h01 = HeightAtCell(cx.index, cy.index + 1);
  const double h11 = HeightAtCell(cx.index + 1, cy.index + 1);
  const double bottom = h00 + cx.fraction * (h10 - h00);
  const double top = h01 + cx.fraction * (h11 - h01);
  return bottom + cy.fraction * (top - bottom);
}

Eigen::Vector2d Heightfield::GradientAt(double x_m, double y_m) const {
  if (cols_ < 2 || rows_ < 2) return Eigen::Vector2d::Zero();
  const CellCoordinate cx = LocateClamped(x_m, origin_xy_.x(), resolution_m_, cols_);
  const CellCoordinate cy = LocateClamped(y_m, origin_xy_.y(), resolution_m_, rows_);
  const double h00 = HeightAtCell(cx.index, cy.index);
  const double h10 = HeightAtCell(cx.index + 1, cy.index);
  const double h01 = HeightAtCell(cx.index, cy.index + 1);
  const double h11 = HeightAtCell(cx.index + 1, cy.index + 1);
  Eigen::Vector2d gradient;
  gradient.x() =
      cx.clamped ? 0.0
                 : ((h10 - h00) * (1.0 - cy.fraction) + (h11 - h01) * cy.fraction) / resolution_m_;
  gradient.y() =
      cy.clamped ? 0.0
                 : ((h01 - h00) * (1.0 - cx.fraction) + (h11 - h10) * cx.fraction) / resolution_m_;
  return gradient;
}

Eigen::Vector3d Heightfield::NormalAt(double x_m, double y_m) const {
  const Eigen::Vector2d g = GradientAt(x_m, y_m);
  return Eigen::Vector3d(-g.x(), -g.y(), 1.0).normalized();
}

Eigen::Vector3d Heightfield::SmoothNormalAt(double x_m, double y_m) const {
  if (cols_ < 2 || rows_ < 2) return Eigen::Vector3d::UnitZ();
  const CellCoordinate cx = LocateClamped(x_m, origin_xy_.x(), resolution_m_, cols_);
  const CellCoordinate cy = LocateClamped(y_m, origin_xy_.y(), resolution_m_, rows_);
  // Central differences at a sample, one-sided at the border.
  const auto sample_gradient = [this](int ix, int iy) {
    const int x0 = std::max(ix - 1, 0);
    const int x1 = std::min(ix + 1, cols_ - 1);
    const int y0 = std::max(iy - 1, 0);
    const int y1 = std::min(iy + 1, rows_ - 1);
    return Eigen::Vector2d(static_cast<double>(HeightAtCell(x1, iy) - HeightAtCell(x0, iy)) /
                               (resolution_m_ * (x1 - x0)),
                           static_cast<double>(HeightAtCell(ix, y1) - HeightAtCell(ix, y0)) /
                               (resolution_m_ * (y1 - y0)));
  };
  const Eigen::Vector2d g00 = sample_gradient(cx.index, cy.index);
  const Eigen::Vector2d g10 = sample_gradient(cx.index + 1, cy.index);
  const Eigen::Vector2d g01 = sample_gradient(cx.index, cy.index + 1);
  const Eigen::Vector2d g11 = sample_gradient(cx.index + 1, cy.index + 1);
  const Eigen::Vector2d bottom = g00 + cx.fraction * (g10 - g00);
  const Eigen::Vector2d top = g01 + cx.fraction * (g11 - g01);
  const Eigen::Vector2d g = bottom + cy.fraction * (top - bottom);
  return Eigen::Vector3d(-g.x(), -g.y(), 1.0).normalized();
}

bool Heightfield::Raycast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                          double max_range_m, double* range_m) const {
  if (cols_ < 2 || rows_ < 2 || !(max_range_m >= 0.0) || !direction.allFinite() ||
      !origin.allFinite() || direction.isZero(0.0)) {
    return false;
  }
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const Eigen::Vector2d lo = origin_xy_;
  const Eigen::Vector2d hi = max_xy();

  // Clip the ray to the grid's xy extent (slab method).
  double t_begin = 0.0;
  double t_end = max_range_m;
  for (int axis = 0; axis < 2; ++axis) {
    const double o = origin[axis];
    const double d = direction[axis];
    if (d == 0.0) {
      if (o < lo[axis] || o > hi[axis]) return false;
      continue;
    }
    double t0 = (lo[axis] - o) / d;
    double t1 = (hi[axis] - o) / d;
    if (t0 > t1) std::swap(t0, t1);
    t_begin = std::max(t_begin, t0);
    t_end = std::min(t_end, t1);
  }
  // Skip the stretches where the ray is above the highest sample, and stop
  // once it is below the lowest: no crossing can lie there.
  const double dz = direction.z();
  if (dz == 0.0) {
    if (origin.z() > max_height_m_) return false;
  } else {
    const double t_at_max = (max_height_m_ - origin.z()) / dz;
    const double t_at_min = (min_height_m_ - origin.z()) / dz;
    if (dz < 0.0) {
      t_begin = std::max(t_begin, t_at_max);
      // The crossing lies before the ray leaves the height band; a small
      // margin keeps the endpoint inside a cell evaluation.
      t_end = std::min(t_end, t_at_min + 1e-9);
    } else {
      t_end = std::min(t_end, t_at_max);
    }
  }
  if (!(t_begin <= t_end)) return false;

  const double res = resolution_m_;
  const double inv_res = 1.0 / res;
  // Cell under the ray at t_begin.
  const auto cell_of = [&](int axis, double t, int count) {
    const double u = (origin[axis] + direction[axis] * t - lo[axis]) * inv_res;
    return std::clamp(static_cast<int>(std::floor(u)), 0, count - 2);
  };
  int ix = cell_of(0, t_begin, cols_);
  int iy = cell_of(1, t_begin, rows_);
  const int step_x = direction.x() > 0.0 ? 1 : -1;
  const int step_y = direction.y() > 0.0 ? 1 : -1;
  // Ray parameter at which it crosses the next cell border along each axis.
  const auto next_border = [&](int axis, int index, int step) {
    const double d = direction[axis];
    if (d == 0.0) return kInf;
    const double border = lo[axis] + res * static_cast<double>(step > 0 ? index + 1 : index);
    return (border - origin[axis]) / d;
  };
  double t_next_x = next_border(0, ix, step_x);
  double t_next_y = next_border(1, iy, step_y);
  const double t_delta_x = direction.x() == 0.0 ? kInf : res / std::abs(direction.x());
  const double t_delta_y = direction.y() == 0.0 ? kInf : res / std::abs(direction.y());

  double t_a = t_begin;
  while (true) {
    const double t_b = std::min({t_next_x, t_next_y, t_end});
    // Height of the ray above the cell's bilinear patch; quadratic in t.
    const double x0 = lo.x() + res * ix;
    const double y0 = lo.y() + res * iy;
    const double h00 = HeightAtCell(ix, iy);
    const double h10 = HeightAtCell(ix + 1, iy);
    const double h01 = HeightAtCell(ix, iy + 1);
    const double h11 = HeightAtCell(ix + 1, iy + 1);
    const auto clearance = [&](double t) {
      const double u = (origin.x() + direction.x() * t - x0) * inv_res;
      const double v = (origin.y() + direction.y() * t - y0) * inv_res;
      const double bottom = h00 + u * (h10 - h00);
      const double top = h01 + u * (h11 - h01);
      return origin.z() + dz * t - (bottom + v * (top - bottom));
    };
    const double f_a = clearance(t_a);
    if (f_a <= 0.0) {
      *range_m = t_a;
      return true;
    }
    if (t_b > t_a) {
      // The patch's curvature along the ray: f(t) = f_a + b s + a s^2, s = t - t_a.
      const double a = -(h00 - h10 - h01 + h11) * direction.x() * direction.y() * inv_res * inv_res;
      const double f_b = clearance(t_b);
      double bracket_hi = kInf;
      if (f_b <= 0.0) {
        bracket_hi = t_b;
      } else if (a > 0.0) {
        // Convex: the clearance may dip below zero between the ends.
        const double slope_a = (f_b - f_a) / (t_b - t_a) - a * (t_b - t_a);
        const double t_min = t_a - slope_a / (2.0 * a);
        if (t_min > t_a && t_min < t_b && clearance(t_min) <= 0.0) bracket_hi = t_min;
      }
      if (bracket_hi != kInf) {
        // Exactly one sign change in [t_a, bracket_hi]: bisect.
        double low = t_a;
        double high = bracket_hi;
        while (high - low > 1e-7) {
          const double mid = 0.5 * (low + high);
          if (clearance(mid) > 0.0) {
            low = mid;
          } else {
            high = mid;
          }
        }
        *range_m = high;
        return true;
      }
    }
    if (t_b >= t_end) return false;
    // Step into the next cell (both axes at a corner).
    const bool step_in_x = t_next_x <= t_next_y;
    const bool step_in_y = t_next_y <= t_next_x;
    if (step_in_x) {
      ix += step_x;
      t_next_x += t_delta_x;
    }
    if (step_in_y) {
      iy += step_y;
      t_next_y += t_delta_y;
    }
    if (ix < 0 || ix > cols_ - 2 || iy < 0 || iy > rows_ - 2) return false;
    t_a = t_b;
  }
}

double AlbedoMap::At(double x_m, double y_m) const {
  if (cols < 2 || rows < 2 ||
      values.size() < static_cast<std::size_t>(cols) * static_cast<std::size_t>(rows))
    return 0.0;
  const CellCoordinate cx = LocateClamped(x_m, origin_xy.x(), resolution_m, cols);
  const CellCoordinate cy = LocateClamped(y_m, origin_xy.y(), resolution_m, rows);
  const auto value = [this](int ix, int iy) {
    return static_cast<double>(
        values[static_cast<std::size_t>(iy) * static_cast<std::size_t>(cols) +
               static_cast<std::size_t>(ix)]);
  };
  const double v00 = value(cx.index, cy.index);
  const double v10 = value(cx.index + 1, cy.index);
  const double v01 = value(cx.index, cy.index + 1);
  const double v11 = value(cx.index + 1, cy.index + 1);
  const double bottom = v00 + cx.fraction * (v10 - v00);
  const double top = v01 + cx.fraction * (v11 - v01);
  return (bottom + cy.fraction * (top - bottom)) / 255.0;
}

}  // namespace rover::sim
