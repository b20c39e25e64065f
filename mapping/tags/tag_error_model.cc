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

using Vector8d = Eigen::Matrix<double, 8, 1>;

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
  CheckPositive(kName, "small_tag_side_px", small_tag_side_px);
  CheckRange(kName, "flip_sigma_factor", flip_sigma_factor, 1.0, 100.0);
  CheckRange(kName, "max_tilt_deg", max_tilt_deg, 1.0, 89.0);
  CheckPositive(kName, "max_reprojection_rmse_px", max_reprojection_rmse_px);
  CheckRange(kName, "max_flipped_fraction", max_flipped_fraction, 0.0, 1.0);
  CheckRange(kName, "max_ambiguity_ratio", max_ambiguity_ratio, 0.0, 1.0);
}

Matrix6d AnalyticTagCovariance(const Eigen::Isometry3d& T_camera_tag, double tag_size_m,
                               const calib::RectifiedIntrinsics& camera, double corner_sigma_px) {
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
  const Matrix6d information = J.transpose() * J / (corner_sigma_px * corner_sigma_px);
  // Nearly singular when the tag is tiny or seen edge-on: the pseudo-inverse
  // then leaves a direction unconstrained, so refuse that case upstream by
  // the huge variance it implies instead.
  return information.completeOrthogonalDecomposition().pseudoInverse();
}

double CornerSigmaPx(const TagErrorModelOptions& options, const Eigen::Isometry3d& T_camera_tag,
                     double tag_size_m, const calib::RectifiedIntrinsics& camera, int flipped) {
  const std::array<Eigen::Vector2d, 4> c = ProjectTagCorners(T_camera_tag, tag_size_m, camera);
  double side_px = 0.0;
  for (std::size_t k = 0; k < 4; ++k) side_px += (c[(k + 1) % 4] - c[k]).norm() / 4.0;
  // Foreshortening shortens two edges and spreads each edge's pixels over a
  // wider blur: the corners lose accuracy about as 1/cos(tilt).
  const double cos_tilt =
      std::max(std::cos(TagTilt(T_camera_tag)), std::cos(options.max_tilt_deg * M_PI / 180.0));
  double sigma = options.corner_sigma_px / cos_tilt;
  if (side_px < options.small_tag_side_px) {
    sigma *= std::pow(options.small_tag_side_px / std::max(side_px, 1.0), 0.75);
  }
  if (flipped > 0) sigma *= options.flip_sigma_factor;
  return sigma;
}

TagErrorModel::TagErrorModel(const TagErrorModelOptions& options,
                             std::optional<TagErrorTable> table)
    : options_(options), table_(std::move(table)) {
  options_.Validate();
  if (options_.kind == TagErrorModelKind::kTable && !table_) {
    throw std::invalid_argument("TagErrorModel: the table model needs a tag error table");
  }
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
    const double sigma_px =
        CornerSigmaPx(options_, pose.best.T_camera_tag, tag_size_m, camera, u.perturbation.flipped);
    u.covariance = AnalyticTagCovariance(pose.best.T_camera_tag, tag_size_m, camera, sigma_px);
    u.sigma = u.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
  }
  if (!u.covariance.allFinite() || !(u.sigma.array() > 0.0).all()) {
    u.refusal = "degenerate covariance";
    return u;
  }
  u.accepted = true;
  return u;
}

TagUncertainty TagErrorModel::Inflated(const TagPose& pose, const TagUncertainty& best) {
  TagUncertainty u = best;
  if (!u.accepted) return u;
  const TagPoseErrors d = 2.0 * TagPoseError(pose.best.T_camera_tag, pose.alternative.T_camera_tag);
  u.covariance += d * d.transpose();
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
    const double sigma_px = CornerSigmaPx(options_, T_camera_tag, tag_size_m, camera, 1);
    u.covariance = AnalyticTagCovariance(T_camera_tag, tag_size_m, camera, sigma_px);
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
