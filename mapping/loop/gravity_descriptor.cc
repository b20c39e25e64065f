#include "mapping/loop/gravity_descriptor.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <stdexcept>
#include <string>

#include <Eigen/Eigenvalues>

#include "mapping/loop/option_checks.h"

namespace rover::mapping {
namespace {

using loop_internal::CheckPositive;
using loop_internal::CheckRange;

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// Linear interpolation of a coordinate over `bins` bins of unit width whose
// centres sit at 0.5, 1.5, ...: the two bins and the weight of the upper one.
// Outside the centre range all weight goes to the edge bin.
struct Split {
  int lo = 0;
  int hi = 0;
  float w_hi = 0.0f;
};

Split Interpolate(float coordinate, int bins) {
  const float c = coordinate - 0.5f;
  if (c <= 0.0f) return {0, 0, 0.0f};
  if (c >= static_cast<float>(bins - 1)) return {bins - 1, bins - 1, 0.0f};
  const int lo = static_cast<int>(c);
  return {lo, lo + 1, c - static_cast<float>(lo)};
}

// The same, circular (azimuth sectors).
Split InterpolateCircular(float coordinate, int bins) {
  float c = coordinate - 0.5f;
  if (c < 0.0f) c += static_cast<float>(bins);
  int lo = static_cast<int>(c);
  const float w_hi = c - static_cast<float>(lo);
  lo %= bins;
  return {lo, (lo + 1) % bins, w_hi};
}

// Uphill direction of the support's best-fit plane, weighted by
// (radius - distance) so that the keypoint's own surface counts most.
void YawReference(const std::vector<Eigen::Vector3f>& points, const std::vector<Neighbour>& support,
                  const Eigen::Vector3f& keypoint, float radius_m, float* yaw_rad,
                  float* strength) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  double weight_sum = 0.0;
  for (const Neighbour& n : support) {
    const double w = radius_m - std::sqrt(n.distance_sq);
    mean += w * (points[n.index] - keypoint).cast<double>();
    weight_sum += w;
  }
  *yaw_rad = 0.0f;
  *strength = 0.0f;
  if (weight_sum <= 0.0) return;
  mean /= weight_sum;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Neighbour& n : support) {
    const double w = radius_m - std::sqrt(n.distance_sq);
    const Eigen::Vector3d d = (points[n.index] - keypoint).cast<double>() - mean;
    cov.noalias() += w * d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  Eigen::Vector3d normal = eig.eigenvectors().col(0);
  if (normal.z() < 0.0) normal = -normal;
  const Eigen::Vector2d uphill = -normal.head<2>();
  *strength = static_cast<float>(uphill.norm());
  *yaw_rad = static_cast<float>(std::atan2(uphill.y(), uphill.x()));
}

}  // namespace

void GravityDescriptorOptions::Validate() const {
  constexpr const char* kC = "GravityDescriptorOptions";
  CheckPositive(kC, "radius_m", radius_m);
  CheckRange(kC, "azimuth_sectors", azimuth_sectors, 2, 64);
  CheckRange(kC, "radial_shells", radial_shells, 1, 8);
  CheckRange(kC, "elevation_layers", elevation_layers, 1, 8);
  CheckRange(kC, "normal_bins", normal_bins, 1, 32);
  CheckRange(kC, "min_support_points", min_support_points, 1, 1e6);
}

GravityDescriptorOptions GravityDescriptorOptions::Load(const ConfigNode& node) {
  GravityDescriptorOptions o;
  o.kind = node.GetEnum<GravityDescriptorKind>("kind",
                                               {{"fourier", GravityDescriptorKind::kFourier},
                                                {"oriented", GravityDescriptorKind::kOriented}},
                                               o.kind);
  o.radius_m = node.Get<double>("radius_m", o.radius_m);
  o.azimuth_sectors = node.Get<int>("azimuth_sectors", o.azimuth_sectors);
  o.radial_shells = node.Get<int>("radial_shells", o.radial_shells);
  o.elevation_layers = node.Get<int>("elevation_layers", o.elevation_layers);
  o.normal_bins = node.Get<int>("normal_bins", o.normal_bins);
  o.min_support_points = node.Get<int>("min_support_points", o.min_support_points);
  o.Validate();
  return o;
}

int GravityDescriptorOptions::Length() const {
  const int rings = radial_shells * elevation_layers * normal_bins;
  return kind == GravityDescriptorKind::kFourier ? rings * (azimuth_sectors / 2 + 1)
                                                 : rings * azimuth_sectors;
}

KeypointDescriptors ComputeGravityDescriptors(const PointKdTree& cloud,
                                              const std::vector<Eigen::Vector3f>& normals,
                                              const std::vector<Eigen::Vector3f>& keypoints,
                                              const GravityDescriptorOptions& options) {
  options.Validate();
  if (normals.size() != cloud.size()) {
    throw std::invalid_argument("ComputeGravityDescriptors: " + std::to_string(normals.size()) +
                                " normals for " + std::to_string(cloud.size()) +
                                " points (expected one per point)");
  }
  const int S = options.azimuth_sectors;
  const int R = options.radial_shells;
  const int E = options.elevation_layers;
  const int B = options.normal_bins;
  const auto Sf = static_cast<float>(S);
  const auto Rf = static_cast<float>(R);
  const auto Ef = static_cast<float>(E);
  const auto Bf = static_cast<float>(B);
  const auto radius = static_cast<float>(options.radius_m);
  const std::vector<Eigen::Vector3f>& points = cloud.points();

  KeypointDescriptors out;
  const auto n = static_cast<Eigen::Index>(keypoints.size());
  out.descriptors = Eigen::MatrixXf::Zero(n, options.Length());
  out.yaw_reference_rad.assign(keypoints.size(), 0.0f);
  out.yaw_reference_strength.assign(keypoints.size(), 0.0f);
  out.valid.assign(keypoints.size(), false);

  // Histogram cells, sector fastest: h[((r * E + e) * B + b) * S + s].
  std::vector<float> h(static_cast<std::size_t>(S * R * E * B));
  std::vector<Neighbour> support;
  for (Eigen::Index k = 0; k < n; ++k) {
    const Eigen::Vector3f& key = keypoints[static_cast<std::size_t>(k)];
    cloud.Radius(key, radius, &support);
    if (static_cast<int>(support.size()) < options.min_support_points) continue;
    float yaw = 0.0f;
    float strength = 0.0f;
    YawReference(points, support, key, radius, &yaw, &strength);
    out.yaw_reference_rad[static_cast<std::size_t>(k)] = yaw;
    out.yaw_reference_strength[static_cast<std::size_t>(k)] = strength;
    const float azimuth_origin = options.kind == GravityDescriptorKind::kOriented ? yaw : 0.0f;

    std::fill(h.begin(), h.end(), 0.0f);
    for (const Neighbour& nb : support) {
      const Eigen::Vector3f d = points[nb.index] - key;
      const float distance = std::sqrt(nb.distance_sq);
      float azimuth = std::atan2(d.y(), d.x()) - azimuth_origin;
      azimuth -= static_cast<float>(kTwoPi) * std::floor(azimuth / static_cast<float>(kTwoPi));
      const Split s = InterpolateCircular(azimuth / static_cast<float>(kTwoPi) * Sf, S);
      const Split r = Interpolate(distance / radius * Rf, R);
      const Split e = Interpolate((d.z() / radius + 1.0f) * 0.5f * Ef, E);
      const Split b = Interpolate(std::abs(normals[nb.index].z()) * Bf, B);
      for (int is = 0; is < 2; ++is) {
        const int si = is ? s.hi : s.lo;
        const float ws = is ? s.w_hi : 1.0f - s.w_hi;
        for (int ir = 0; ir < 2; ++ir) {
          const int ri = ir ? r.hi : r.lo;
          const float wr = ws * (ir ? r.w_hi : 1.0f - r.w_hi);
          for (int ie = 0; ie < 2; ++ie) {
            const int ei = ie ? e.hi : e.lo;
            const float we = wr * (ie ? e.w_hi : 1.0f - e.w_hi);
            for (int ib = 0; ib < 2; ++ib) {
              const int bi = ib ? b.hi : b.lo;
              const float w = we * (ib ? b.w_hi : 1.0f - b.w_hi);
              h[static_cast<std::size_t>(((ri * E + ei) * B + bi) * S + si)] += w;
            }
          }
        }
      }
    }

    auto row = out.descriptors.row(k);
    if (options.kind == GravityDescriptorKind::kOriented) {
      for (std::size_t i = 0; i < h.size(); ++i) row(static_cast<Eigen::Index>(i)) = h[i];
    } else {
      // |DFT| over the sectors of each ring: a yaw rotation by a whole
      // sector shifts them circularly and leaves the magnitudes unchanged
      // (between sectors the interpolation makes the change small).
      const int harmonics = S / 2 + 1;
      for (int ring = 0; ring < R * E * B; ++ring) {
        const float* sectors = &h[static_cast<std::size_t>(ring * S)];
        for (int f = 0; f < harmonics; ++f) {
          std::complex<double> sum = 0.0;
          for (int si = 0; si < S; ++si) {
            sum += static_cast<double>(sectors[si]) * std::polar(1.0, -kTwoPi * f * si / S);
          }
          row(ring * harmonics + f) = static_cast<float>(std::abs(sum));
        }
      }
    }
    const float norm = row.norm();
    if (norm > 0.0f) {
      row /= norm;
      out.valid[static_cast<std::size_t>(k)] = true;
    }
  }
  return out;
}

}  // namespace rover::mapping
