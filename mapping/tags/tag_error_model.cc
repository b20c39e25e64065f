#include "mapping/tags/tag_error_model.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "core/geometry/so3.h"
#include "mapping/loop/option_checks.h"

namespace rover::mapping {
namespace {

using loop_internal::CheckPositive;
using loop_internal::CheckRange;

Vector8d Corners(const Eigen::Isometry3d& T, double s, const calib::RectifiedIntrinsics& camera) {
  const std::array<Eigen::Vector2d, 4> c = ProjectTagCorners(T, s, camera);
  Vector8d v;
  for (int k = 0; k < 4; ++k) v.segment<2>(2 * k) = c[static_cast<std::size_t>(k)];
  return v;
}

// T (+) delta in the parametrisation of TagPoseErrors.
Eigen::Isometry3d Perturbed(const Eigen::Isometry3d& T, const TagPoseErrors& delta) {
  Eigen::Isometry3d out = T;
  out.translation() += delta.head<3>();
  out.linear() = T.linear() * ExpSO3(delta.tail<3>());
  return out;
}

}  // namespace

void TagErrorModelOptions::Validate() const {
  constexpr const char* kName = "TagErrorModelOptions";
  CheckRange(kName, "corner_delta_px", corner_delta_px, 0.0, 10.0);
  CheckPositive(kName, "sigma_per_max_error", sigma_per_max_error);
  CheckPositive(kName, "corner_sigma_px", corner_sigma_px);
  CheckRange(kName, "tilt_sigma_exponent", tilt_sigma_exponent, 0.0, 2.0);
  CheckRange(kName, "frontal_sigma_gain", frontal_sigma_gain, 0.0, 10.0);
  CheckRange(kName, "frontal_tilt_deg", frontal_tilt_deg, 1.0, 89.0);
  CheckRange(kName, "aligned_edge_sigma_px", aligned_edge_sigma_px, 0.0, 10.0);
  CheckPositive(kName, "small_tag_side_px", small_tag_side_px);
  CheckRange(kName, "flip_sigma_factor", flip_sigma_factor, 1.0, 100.0);
  CheckRange(kName, "max_tilt_deg", max_tilt_deg, 1.0, 89.0);
  CheckPositive(kName, "max_reprojection_rmse_px", max_reprojection_rmse_px);
  CheckRange(kName, "max_flipped_fraction", max_flipped_fraction, 0.0, 1.0);
  CheckRange(kName, "max_ambiguity_ratio", max_ambiguity_ratio, 0.0, 1.0);
}

Matrix6d AnalyticTagCovariance(const Eigen::Isometry3d& T_camera_tag, double tag_size_m,
                               const calib::RectifiedIntrinsics& camera, double corner_sigma_px) {
  return AnalyticTagCovariance(T_camera_tag, tag_size_m, camera,
                               Matrix8d::Identity() * corner_sigma_px * corner_sigma_px);
}

Matrix8d AlignedEdgeCovariance(const std::array<Eigen::Vector2d, 4>& corners_px,
                               double edge_sigma_px) {
  Matrix8d C = Matrix8d::Zero();
  for (int k = 0; k < 4; ++k) {
    const auto at = [&](int i) { return corners_px[static_cast<std::size_t>((i + 4) % 4)]; };
    const Eigen::Vector2d edge = at(k + 1) - at(k);
    const double length_px = edge.norm();
    if (length_px < 1e-9) continue;
    const Eigen::Vector2d t = edge / length_px;
    const Eigen::Vector2d n(-t.y(), t.x());
    // The edge's pixel phase sweeps length * sin(angle to the nearest pixel
    // axis) pixels along it: beyond one pixel its offset errors average out.
    const double sweep_px = length_px * std::min(std::abs(t.x()), std::abs(t.y()));
    const double weight = std::max(0.0, 1.0 - sweep_px);
    if (weight <= 0.0) continue;
    // Shifting edge k by one pixel along n slides its corners along their
    // other edges (k-1 at corner k, k+1 at corner k+1).
    Vector8d g = Vector8d::Zero();
    const Eigen::Vector2d t_before = (at(k) - at(k - 1)).normalized();
    const Eigen::Vector2d t_after = (at(k + 2) - at(k + 1)).normalized();
    const double c_before = n.dot(t_before), c_after = n.dot(t_after);
    if (std::abs(c_before) < 0.1 || std::abs(c_after) < 0.1) continue;  // degenerate quad
    g.segment<2>(2 * k) = t_before / c_before;
    g.segment<2>(2 * ((k + 1) % 4)) = t_after / c_after;
    C += weight * edge_sigma_px * edge_sigma_px * g * g.transpose();
  }
  return C;
}

Matrix6d AnalyticTagCovariance(const Eigen::Isometry3d& T_camera_tag, double tag_size_m,
                               const calib::RectifiedIntrinsics& camera,
                               const Matrix8d& corner_covariance) {
  // Central differences: the projection is smooth and this runs once per
  // detection.
  Eigen::Matrix<double, 8, 6> J;
  for (int k = 0; k < 6; ++k) {
    const double h = k < 3 ? 1e-6 * std::max(1.0, T_camera_tag.translation().norm()) : 1e-6;
    TagPoseErrors d = TagPoseErrors::Zero();
    d[k] = h;
    J.col(k) = (Corners(Perturbed(T_camera_tag, d), tag_size_m, camera) -
                Corners(Perturbed(T_camera_tag, -d), tag_size_m, camera)) /
               (2.0 * h);
  }
  // The pose minimises the unweighted reprojection error: dx = P dc with
  // P = (J^T J)^-1 J^T, so Sigma = P C P^T. Nearly singular when the tag is
  // tiny or seen edge-on: the pseudo-inverse then leaves a direction
  // unconstrained, so refuse that case upstream by the huge variance it
  // implies instead.
  const Eigen::Matrix<double, 6, 8> P =
      (J.transpose() * J).completeOrthogonalDecomposition().pseudoInverse() * J.transpose();
  return P * corner_covariance * P.transpose();
}

double CornerSigmaPx(const TagErrorModelOptions& options, const Eigen::Isometry3d& T_camera_tag,
                     double tag_size_m, const calib::RectifiedIntrinsics& camera, int flipped) {
  const std::array<Eigen::Vector2d, 4> c = ProjectTagCorners(T_camera_tag, tag_size_m, camera);
  double side_px = 0.0;
  for (std::size_t k = 0; k < 4; ++k) side_px += (c[(k + 1) % 4] - c[k]).norm() / 4.0;
  // Foreshortening shortens two edges and spreads each edge's pixels over a
  // wider blur, but the Jacobian already carries the geometry: the corners
  // themselves lose accuracy only about as sqrt(1/cos(tilt)).
  const double tilt_rad = std::abs(TagTilt(T_camera_tag));
  const double cos_tilt =
      std::max(std::cos(tilt_rad), std::cos(options.max_tilt_deg * M_PI / 180.0));
  double sigma = options.corner_sigma_px * std::pow(1.0 / cos_tilt, options.tilt_sigma_exponent);
  // Near head-on the two solutions of the planar ambiguity close in and the
  // tilt is pulled further than the linearisation says.
  const double frontal_rad = options.frontal_tilt_deg * M_PI / 180.0;
  sigma *= 1.0 + options.frontal_sigma_gain * std::max(0.0, 1.0 - tilt_rad / frontal_rad);
  if (side_px < options.small_tag_side_px) {
    sigma *= std::pow(options.small_tag_side_px / std::max(side_px, 1.0), 0.75);
  }
  if (flipped > 0) sigma *= options.flip_sigma_factor;
  return sigma;
}

Matrix8d AnalyticCornerCovariance(const TagErrorModelOptions& options,
                                  const Eigen::Isometry3d& T_camera_tag, double tag_size_m,
                                  const calib::RectifiedIntrinsics& camera, double sigma_px) {
  // The grid-aligned edges' offsets grow with the same factor as the
  // independent corner noise.
  const double scale = sigma_px / options.corner_sigma_px;
  Matrix8d C = Matrix8d::Identity() * sigma_px * sigma_px;
  if (options.aligned_edge_sigma_px > 0.0) {
    C += AlignedEdgeCovariance(ProjectTagCorners(T_camera_tag, tag_size_m, camera),
                               scale * options.aligned_edge_sigma_px);
  }
  return C;
}

TagErrorModel::TagErrorModel(const TagErrorModelOptions& options,
                             std::optional<TagErrorTable> table)
    : options_(options), table_(std::move(table)) {
  options_.Validate();
  if (options_.kind == TagErrorModelKind::kTable && !table_) {
    throw std::invalid_argument("TagErrorModel: the table model needs a tag error table");
  }
}

Matrix6d TagErrorModel::AnalyticCovariance(const Eigen::Isometry3d& T_camera_tag, double tag_size_m,
                                           const calib::RectifiedIntrinsics& camera,
                                           int flipped) const {
  const double sigma_px = CornerSigmaPx(options_, T_camera_tag, tag_size_m, camera, flipped);
  return AnalyticTagCovariance(
      T_camera_tag, tag_size_m, camera,
      AnalyticCornerCovariance(options_, T_camera_tag, tag_size_m, camera, sigma_px));
}

TagUncertainty TagErrorModel::Evaluate(const std::array<Eigen::Vector2d, 4>& corners_px,
                                       const TagPose& pose, double tag_size_m,
                                       const calib::RectifiedIntrinsics& camera) const {
  TagUncertainty u;
  u.perturbation = PerturbCorners(corners_px, tag_size_m, camera, options_.corner_delta_px);
  std::ostringstream why;
  const double flipped = u.perturbation.flipped / 256.0;
  if (u.perturbation.solved == 0) {
    why << "no pose for the detected corners";
  } else if (pose.best.reprojection_rmse_px > options_.max_reprojection_rmse_px) {
    why << "the corners do not fit a square of the tag's size: reprojection RMSE "
        << pose.best.reprojection_rmse_px << " px (at most " << options_.max_reprojection_rmse_px
        << "), a corner misplaced";
  } else if (std::abs(pose.tilt_rad) > options_.max_tilt_deg * M_PI / 180.0) {
    why << "seen nearly edge-on: tilt " << std::abs(pose.tilt_rad) * 180.0 / M_PI
        << " deg (at most " << options_.max_tilt_deg << ")";
  } else if (flipped > options_.max_flipped_fraction) {
    why << "ambiguous: " << u.perturbation.flipped << " of 256 perturbed poses flip to the other "
        << "solution";
    u.ambiguous = true;
  } else if (pose.ambiguity_ratio > options_.max_ambiguity_ratio) {
    why << "ambiguous: the two solutions fit within a ratio of " << pose.ambiguity_ratio
        << " (at most " << options_.max_ambiguity_ratio << ")";
    u.ambiguous = true;
  }
  u.refusal = why.str();
  if (!u.refusal.empty()) return u;
  if (options_.kind == TagErrorModelKind::kTable) {
    const TagPoseErrors base = table_->Lookup(pose.distance_m, pose.tilt_rad);
    u.sigma = options_.sigma_per_max_error * base.cwiseMax(u.perturbation.max_deviation);
    u.covariance = LineOfSightCovariance(u.sigma, pose.best.T_camera_tag.translation());
  } else {
    u.covariance =
        AnalyticCovariance(pose.best.T_camera_tag, tag_size_m, camera, u.perturbation.flipped);
    u.sigma = u.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
  }
  if (!u.covariance.allFinite() || !(u.sigma.array() > 0.0).all()) {
    u.refusal = "degenerate covariance";
    return u;
  }
  u.accepted = true;
  return u;
}

TagUncertainty TagErrorModel::Inflated(const TagPose& pose, const TagUncertainty& best,
                                       const TagUncertainty* alternative) {
  TagUncertainty u = best;
  if (!u.accepted) return u;
  const TagPoseErrors d = 2.0 * TagPoseError(pose.best.T_camera_tag, pose.alternative.T_camera_tag);
  u.covariance += d * d.transpose();
  if (alternative != nullptr && alternative->accepted) {
    u.covariance.bottomRightCorner<3, 3>() += alternative->covariance.bottomRightCorner<3, 3>();
  }
  u.sigma = u.covariance.diagonal().cwiseSqrt();
  u.ambiguous = true;
  return u;
}

TagUncertainty TagErrorModel::ForSolution(const Eigen::Isometry3d& T_camera_tag, double tag_size_m,
                                          const calib::RectifiedIntrinsics& camera,
                                          const CornerPerturbation* perturbation) const {
  TagUncertainty u;
  if (perturbation != nullptr) u.perturbation = *perturbation;  // logged with the detection
  if (options_.kind == TagErrorModelKind::kTable) {
    TagPoseErrors max_error =
        table_->Lookup(T_camera_tag.translation().norm(), TagTilt(T_camera_tag));
    if (perturbation != nullptr) {
      max_error.head<3>() = max_error.head<3>().cwiseMax(perturbation->max_deviation.head<3>());
    }
    u.sigma = options_.sigma_per_max_error * max_error;
    u.covariance = LineOfSightCovariance(u.sigma, T_camera_tag.translation());
  } else {
    // Chosen between two solutions: as close to the ambiguity as a flipping
    // detection, whatever the perturbation counted.
    u.covariance = AnalyticCovariance(T_camera_tag, tag_size_m, camera, 1);
    u.sigma = u.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
  }
  if (!u.covariance.allFinite() || !(u.sigma.array() > 0.0).all()) {
    u.refusal = "degenerate covariance";
    return u;
  }
  u.accepted = true;
  return u;
}

}  // namespace rover::mapping
