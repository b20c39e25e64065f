#include "mapping/tags/tag_border_fit.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

#include <Eigen/LU>

namespace rover::mapping {
namespace {

constexpr double kStepPx = 0.25;                 // profile sampling along the normal
constexpr std::size_t kMaxProfileSamples = 257;  // caps the half window at 32 px
constexpr std::size_t kMinProfiles = 5;
constexpr std::size_t kMaxProfiles = 16;
constexpr double kProfileSpacingPx = 3.0;
// Profiles within this fraction of a side's ends would cross the other side.
constexpr double kEndMargin = 0.1;
// The window's half width in bits: clear of the data bits inside the border
// ring (one bit in) and of the margin's outer edge (one bit out).
constexpr double kHalfWindowBits = 0.75;
constexpr double kMinHalfWindowPx = 1.0;
// The gradient lobe around the peak ends where it falls below this fraction
// of the peak: at half, a sharp step's plateau is kept whole, and the weaker
// step of a carrier's edge a bit further out, blurred into the same lobe, is
// cut off instead of pulling the centroid towards it.
constexpr double kLobeFloor = 0.5;
// A step weaker than this fraction of the tag's median step is not the
// border (it is the carrier's edge or noise).
constexpr double kWeakStep = 0.25;
constexpr double kMinSidePx = 4.0;
constexpr double kMinSineBetweenSides = 0.2;

struct Profile {
  double u = 0.0;          // position along the side, 0..1
  double offset_px = 0.0;  // step across the side, outward positive
  double step_dn = 0.0;    // grey levels the step rises by
  bool found = false;
};

// Bilinear grey level at (x, y); false if outside the image.
bool Sample(const cv::Mat& image, double x, double y, double* value) {
  if (!(x >= 0.0 && y >= 0.0 && x < image.cols - 1.0 && y < image.rows - 1.0)) return false;
  const int x0 = static_cast<int>(x);
  const int y0 = static_cast<int>(y);
  const double fx = x - x0;
  const double fy = y - y0;
  const uint8_t* r0 = image.ptr<uint8_t>(y0) + x0;
  const uint8_t* r1 = image.ptr<uint8_t>(y0 + 1) + x0;
  *value = (1.0 - fy) * ((1.0 - fx) * r0[0] + fx * r0[1]) + fy * ((1.0 - fx) * r1[0] + fx * r1[1]);
  return true;
}

// The border step across one profile at `p` along the outward normal `n`,
// within +-half_window_px. Returns false if the profile leaves the image.
bool MeasureProfile(const cv::Mat& image, const Eigen::Vector2d& p, const Eigen::Vector2d& n,
                    double half_window_px, double polarity, Profile* out) {
  const std::size_t half =
      std::min(kMaxProfileSamples / 2, static_cast<std::size_t>(half_window_px / kStepPx));
  const std::size_t samples = 2 * half + 1;
  const double s0 = -kStepPx * static_cast<double>(half);
  const auto offset = [&](std::size_t i) { return s0 + kStepPx * static_cast<double>(i); };
  std::array<double, kMaxProfileSamples> level{};
  for (std::size_t i = 0; i < samples; ++i) {
    const Eigen::Vector2d q = p + offset(i) * n;
    if (!Sample(image, q.x(), q.y(), &level[i])) return false;
  }
  std::array<double, kMaxProfileSamples> gradient{};
  std::size_t peak = 0;
  for (std::size_t i = 1; i + 1 < samples; ++i) {
    gradient[i] = polarity * (level[i + 1] - level[i - 1]) / (2.0 * kStepPx);
    if (gradient[i] > gradient[peak]) peak = i;
  }
  out->found = false;
  // No rise of the border's polarity, or only the flank of a step that lies
  // beyond the window.
  if (peak <= 1 || peak + 2 >= samples || gradient[peak] <= 0.0) return true;
  const double floor = kLobeFloor * gradient[peak];
  std::size_t lo = peak;
  std::size_t hi = peak;
  while (lo > 1 && gradient[lo - 1] > floor) --lo;
  while (hi + 2 < samples && gradient[hi + 1] > floor) ++hi;
  double weight = 0.0;
  double moment = 0.0;
  for (std::size_t i = lo; i <= hi; ++i) {
    weight += gradient[i];
    moment += gradient[i] * offset(i);
  }
  out->offset_px = moment / weight;
  out->step_dn = weight * kStepPx;
  out->found = true;
  return true;
}

using SideProfiles = std::array<Profile, kMaxProfiles>;

// Median of the found profiles' steps (nth_element on a copy).
double MedianStep(const std::array<SideProfiles, 4>& profiles,
                  const std::array<std::size_t, 4>& counts) {
  std::array<double, 4 * kMaxProfiles> steps{};
  std::size_t n = 0;
  for (std::size_t k = 0; k < 4; ++k) {
    for (std::size_t j = 0; j < counts[k]; ++j) {
      if (profiles[k][j].found) steps[n++] = profiles[k][j].step_dn;
    }
  }
  if (n == 0) return 0.0;
  const auto middle = steps.begin() + static_cast<std::ptrdiff_t>(n / 2);
  std::nth_element(steps.begin(), middle, steps.begin() + static_cast<std::ptrdiff_t>(n));
  return *middle;
}

// Least-squares line offset(u) through the found profiles of one side,
// evaluated at u = 0 and 1. Infinite offsets if fewer than two were found.
std::array<double, 2> EndOffsets(const SideProfiles& side, std::size_t count) {
  double n = 0.0, su = 0.0, ss = 0.0, suu = 0.0, sus = 0.0;
  for (std::size_t j = 0; j < count; ++j) {
    const Profile& p = side[j];
    if (!p.found) continue;
    n += 1.0;
    su += p.u;
    ss += p.offset_px;
    suu += p.u * p.u;
    sus += p.u * p.offset_px;
  }
  const double det = n * suu - su * su;
  if (n < 2.0 || !(det > 1e-12)) {
    const double inf = std::numeric_limits<double>::infinity();
    return {inf, inf};
  }
  const double slope = (n * sus - su * ss) / det;
  const double intercept = (ss - slope * su) / n;
  return {intercept, intercept + slope};
}

// How far the border's corner lies from the detected one [px], from the
// border's offsets across the two sides that meet there (outward normals
// n_in, n_out). Sides that meet at a sliver of an angle pin the corner
// poorly along their bisector; the larger offset then stands for it.
double CornerOffset(const Eigen::Vector2d& n_in, double offset_in_px, const Eigen::Vector2d& n_out,
                    double offset_out_px) {
  if (!std::isfinite(offset_in_px) || !std::isfinite(offset_out_px)) {
    return std::numeric_limits<double>::infinity();
  }
  Eigen::Matrix2d normals;
  normals.row(0) = n_in.transpose();
  normals.row(1) = n_out.transpose();
  const double fallback = std::max(std::abs(offset_in_px), std::abs(offset_out_px));
  if (std::abs(normals.determinant()) < kMinSineBetweenSides) return fallback;
  return (normals.inverse() * Eigen::Vector2d(offset_in_px, offset_out_px)).norm();
}

// Takes the profiles across side k; false if the side is too short or a
// profile leaves the image.
bool MeasureSide(const cv::Mat& image, const std::array<Eigen::Vector2d, 4>& corners_px,
                 std::size_t k, const TagBorderGeometry& geometry, SideProfiles* side,
                 std::size_t* count, Eigen::Vector2d* outward) {
  const Eigen::Vector2d centre =
      0.25 * (corners_px[0] + corners_px[1] + corners_px[2] + corners_px[3]);
  const Eigen::Vector2d& a = corners_px[k];
  const Eigen::Vector2d& b = corners_px[(k + 1) % 4];
  const double length_px = (b - a).norm();
  if (!(length_px >= kMinSidePx)) return false;
  const Eigen::Vector2d along = (b - a) / length_px;
  Eigen::Vector2d normal(-along.y(), along.x());
  if (normal.dot(0.5 * (a + b) - centre) < 0.0) normal = -normal;
  // A bit across this side: the quad's extent across it (the shorter of the
  // two sides that meet it, projected on its normal) over the cells across
  // the border. Under a steep tilt that is far less than along the side.
  const Eigen::Vector2d& before = corners_px[(k + 3) % 4];
  const Eigen::Vector2d& after = corners_px[(k + 2) % 4];
  const double across_px =
      std::min(std::abs((a - before).dot(normal)), std::abs((after - b).dot(normal)));
  const double half_window_px =
      std::max(kMinHalfWindowPx, kHalfWindowBits * across_px / geometry.border_cells);
  const double polarity = geometry.reversed ? -1.0 : 1.0;
  *outward = normal;
  *count = std::clamp(static_cast<std::size_t>(length_px / kProfileSpacingPx), kMinProfiles,
                      kMaxProfiles);
  for (std::size_t j = 0; j < *count; ++j) {
    Profile& p = (*side)[j];
    p.u = kEndMargin +
          (1.0 - 2.0 * kEndMargin) * static_cast<double>(j) / static_cast<double>(*count - 1);
    if (!MeasureProfile(image, a + p.u * (b - a), normal, half_window_px, polarity, &p)) {
      return false;
    }
  }
  return true;
}

}  // namespace

TagBorderFit FitTagBorder(const cv::Mat& image, const std::array<Eigen::Vector2d, 4>& corners_px,
                          const TagBorderGeometry& geometry) {
  TagBorderFit fit;
  if (image.empty() || image.type() != CV_8UC1 || geometry.border_cells <= 0) return fit;
  std::array<SideProfiles, 4> profiles{};
  std::array<std::size_t, 4> counts{};
  std::array<Eigen::Vector2d, 4> outward;
  for (std::size_t k = 0; k < 4; ++k) {
    if (!MeasureSide(image, corners_px, k, geometry, &profiles[k], &counts[k], &outward[k])) {
      return fit;
    }
  }
  const double median_step_dn = MedianStep(profiles, counts);
  fit.measured = true;
  for (std::size_t k = 0; k < 4; ++k) {
    std::size_t missing = 0;
    for (std::size_t j = 0; j < counts[k]; ++j) {
      Profile& p = profiles[k][j];
      if (p.found && p.step_dn < kWeakStep * median_step_dn) p.found = false;
      if (!p.found) ++missing;
    }
    fit.missing_fraction[k] = static_cast<double>(missing) / static_cast<double>(counts[k]);
    fit.end_offsets_px[k] = EndOffsets(profiles[k], counts[k]);
  }
  for (std::size_t c = 0; c < 4; ++c) {
    fit.corner_offsets_px[c] =
        CornerOffset(outward[(c + 3) % 4], fit.end_offsets_px[(c + 3) % 4][1], outward[c],
                     fit.end_offsets_px[c][0]);
    if (!(fit.corner_offsets_px[c] <= fit.worst_offset_px)) {
      fit.worst_offset_px = fit.corner_offsets_px[c];
      fit.worst_corner = static_cast<int>(c);
    }
  }
  return fit;
}

}  // namespace rover::mapping
