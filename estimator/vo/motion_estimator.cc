#include "estimator/vo/motion_estimator.h"

#include <opencv2/calib3d.hpp>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <random>

#include "core/geometry/se3.h"
#include "core/geometry/so3.h"

namespace rover::estimator::vo {
namespace {

using Matrix46d = Eigen::Matrix<double, 4, 6>;

Eigen::Isometry3d FromRodrigues(const cv::Mat& rvec, const cv::Mat& tvec) {
  cv::Mat r;
  cv::Rodrigues(rvec, r);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) T.linear()(i, j) = r.at<double>(i, j);
    T.translation()(i) = tvec.at<double>(i, 0);
  }
  return T;
}

}  // namespace

MotionEstimator::MotionEstimator(const calib::RectifiedIntrinsics& intrinsics, double baseline_m,
                                 cv::Size image_size, const MotionEstimatorOptions& options)
    : k_(intrinsics), baseline_m_(baseline_m), size_(image_size), options_(options) {}

bool MotionEstimator::ReprojectionResidual(const Eigen::Isometry3d& T_cur_ref,
                                           const StereoObservation& obs, Eigen::Vector4d* residual,
                                           Matrix46d* jacobian,
                                           Eigen::Matrix<double, 4, 3>* point_jacobian) const {
  const Eigen::Vector3d p = T_cur_ref * obs.p_ref;
  if (!(p.z() > 1e-6)) return false;
  const double iz = 1.0 / p.z();
  const double xr = p.x() - baseline_m_;
  Eigen::Vector4d& r = *residual;
  r(0) = k_.fx * p.x() * iz + k_.cx - obs.left.x();
  r(1) = k_.fy * p.y() * iz + k_.cy - obs.left.y();
  if (obs.has_right) {
    r(2) = k_.fx * xr * iz + k_.cx - obs.right.x();
    r(3) = k_.fy * p.y() * iz + k_.cy - obs.right.y();
  } else {
    r(2) = 0.0;
    r(3) = 0.0;
  }
  if (jacobian != nullptr || point_jacobian != nullptr) {
    // d(pixel)/d(p) for both cameras, times d(p)/d(xi) = [I, -skew(p)]
    // (pose) or d(p)/d(p_ref) = R (point).
    Eigen::Matrix<double, 4, 3> dproj = Eigen::Matrix<double, 4, 3>::Zero();
    dproj(0, 0) = k_.fx * iz;
    dproj(0, 2) = -k_.fx * p.x() * iz * iz;
    dproj(1, 1) = k_.fy * iz;
    dproj(1, 2) = -k_.fy * p.y() * iz * iz;
    if (obs.has_right) {
      dproj(2, 0) = k_.fx * iz;
      dproj(2, 2) = -k_.fx * xr * iz * iz;
      dproj.row(3) = dproj.row(1);
    }
    if (jacobian != nullptr) {
      Eigen::Matrix<double, 3, 6> dp;
      dp.leftCols<3>().setIdentity();
      dp.rightCols<3>() = -skew(p);
      *jacobian = dproj * dp;
    }
    if (point_jacobian != nullptr) *point_jacobian = dproj * T_cur_ref.linear();
  }
  return true;
}

bool MotionEstimator::IsInlier(const Eigen::Isometry3d& T, const StereoObservation& obs) const {
  Eigen::Vector4d r;
  if (!ReprojectionResidual(T, obs, &r)) return false;
  const double t2 = options_.inlier_threshold_px * options_.inlier_threshold_px;
  return r.head<2>().squaredNorm() < t2 && r.tail<2>().squaredNorm() < t2;
}

double MotionEstimator::Spread(const std::vector<StereoObservation>& observations,
                               const std::vector<int>& indices) const {
  const int g = std::max(options_.spread_grid, 1);
  std::vector<char> used(static_cast<size_t>(g * g), 0);
  for (int i : indices) {
    const Eigen::Vector2d& px = observations[static_cast<size_t>(i)].left;
    const int cx = std::clamp(static_cast<int>(px.x() * g / size_.width), 0, g - 1);
    const int cy = std::clamp(static_cast<int>(px.y() * g / size_.height), 0, g - 1);
    used[static_cast<size_t>(cy * g + cx)] = 1;
  }
  const auto n = static_cast<double>(std::count(used.begin(), used.end(), 1));
  return n / static_cast<double>(g * g);
}

Eigen::Matrix4d MotionEstimator::ObservationWeight(const Eigen::Isometry3d& T_cur_ref,
                                                   const StereoObservation& obs) const {
  // Residual covariance S = sigma_px^2 I + Jp Cov(p_ref) Jp^T; the weight is
  // its inverse over the rows the observation has.
  Eigen::Vector4d r;
  Eigen::Matrix<double, 4, 3> Jp;
  Eigen::Matrix4d W = Eigen::Matrix4d::Zero();
  if (!ReprojectionResidual(T_cur_ref, obs, &r, nullptr, &Jp)) return W;
  const double pixel_var = options_.pixel_sigma_px * options_.pixel_sigma_px;
  const Eigen::Matrix4d S =
      pixel_var * Eigen::Matrix4d::Identity() + Jp * obs.p_ref_covariance * Jp.transpose();
  if (obs.has_right) {
    W = S.inverse();
  } else {
    W.topLeftCorner<2, 2>() = S.topLeftCorner<2, 2>().inverse();
  }
  return W;
}

int MotionEstimator::Refine(const std::vector<StereoObservation>& observations,
                            const std::vector<int>& indices, Eigen::Isometry3d* T_cur_ref) const {
  // Weights fixed at the starting pose, so that every iteration minimises
  // the same cost (they change little over the refinement).
  std::vector<Eigen::Matrix4d> weights;
  weights.reserve(indices.size());
  for (int i : indices) {
    weights.push_back(ObservationWeight(*T_cur_ref, observations[static_cast<size_t>(i)]));
  }
  const auto cost_of = [&](const Eigen::Isometry3d& T) {
    double c = 0.0;
    Eigen::Vector4d r;
    for (size_t k = 0; k < indices.size(); ++k) {
      if (!ReprojectionResidual(T, observations[static_cast<size_t>(indices[k])], &r)) {
        return std::numeric_limits<double>::infinity();
      }
      c += r.dot(weights[k] * r);
    }
    return c;
  };
  double lambda = 1e-3;
  double cost = cost_of(*T_cur_ref);
  int it = 0;
  for (; it < options_.lm_max_iterations; ++it) {
    Matrix6d H = Matrix6d::Zero();
    Vector6d g = Vector6d::Zero();
    Eigen::Vector4d r;
    Matrix46d J;
    for (size_t k = 0; k < indices.size(); ++k) {
      if (!ReprojectionResidual(*T_cur_ref, observations[static_cast<size_t>(indices[k])], &r,
                                &J)) {
        continue;
      }
      const Matrix46d WJ = weights[k] * J;
      H.noalias() += J.transpose() * WJ;
      g.noalias() += WJ.transpose() * r;
    }
    bool improved = false;
    Vector6d step = Vector6d::Zero();
    for (int attempt = 0; attempt < 10 && !improved; ++attempt) {
      Matrix6d A = H;
      A.diagonal() += lambda * H.diagonal().cwiseMax(1e-9);
      step = A.ldlt().solve(-g);
      const Eigen::Isometry3d candidate = ExpSE3(step) * *T_cur_ref;
      const double c = cost_of(candidate);
      if (c < cost) {
        *T_cur_ref = candidate;
        cost = c;
        lambda = std::max(lambda * 0.1, 1e-9);
        improved = true;
      } else {
        lambda *= 10.0;
      }
    }
    if (!improved || step.norm() < 1e-10) break;
  }
  return it + 1;
}

MotionEstimate MotionEstimator::Estimate(const std::vector<StereoObservation>& observations) const {
  MotionEstimate out;
  const auto t_start = std::chrono::steady_clock::now();
  out.observations = static_cast<int>(observations.size());
  const int n = out.observations;
  if (n < std::max(options_.min_inliers, 4)) return out;

  // Only finite observations in front of the reference camera are sampled.
  std::vector<int> usable;
  for (int i = 0; i < n; ++i) {
    const StereoObservation& o = observations[static_cast<size_t>(i)];
    if (o.p_ref.allFinite() && o.p_ref.z() > 0.0 && o.left.allFinite() &&
        (!o.has_right || o.right.allFinite())) {
      usable.push_back(i);
    }
  }
  const int n_usable = static_cast<int>(usable.size());
  if (n_usable < std::max(options_.min_inliers, 4)) return out;
  const cv::Matx33d K(k_.fx, 0.0, k_.cx, 0.0, k_.fy, k_.cy, 0.0, 0.0, 1.0);
  std::mt19937_64 rng(options_.seed);
  const auto draw = [&](int bound) {  // same sequence on every platform
    return static_cast<int>(rng() % static_cast<uint64_t>(bound));
  };
  Eigen::Isometry3d best = Eigen::Isometry3d::Identity();
  std::vector<int> best_inliers;
  int max_iterations = options_.ransac_max_iterations;
  int it = 0;
  for (; it < max_iterations; ++it) {
    int s[3];
    s[0] = draw(n_usable);
    do s[1] = draw(n_usable);
    while (s[1] == s[0]);
    do s[2] = draw(n_usable);
    while (s[2] == s[0] || s[2] == s[1]);
    std::vector<cv::Point3d> object;
    std::vector<cv::Point2d> image;
    for (int k : s) {
      const StereoObservation& o =
          observations[static_cast<size_t>(usable[static_cast<size_t>(k)])];
      object.emplace_back(o.p_ref.x(), o.p_ref.y(), o.p_ref.z());
      image.emplace_back(o.left.x(), o.left.y());
    }
    std::vector<cv::Mat> rvecs, tvecs;
    int solutions = 0;
    try {
      solutions = cv::solveP3P(object, image, K, cv::noArray(), rvecs, tvecs, cv::SOLVEPNP_P3P);
    } catch (const cv::Exception&) {
      solutions = 0;  // degenerate sample
    }
    for (int k = 0; k < solutions; ++k) {
      const Eigen::Isometry3d T =
          FromRodrigues(rvecs[static_cast<size_t>(k)], tvecs[static_cast<size_t>(k)]);
      std::vector<int> inliers;
      for (int i : usable) {
        if (IsInlier(T, observations[static_cast<size_t>(i)])) inliers.push_back(i);
      }
      if (inliers.size() > best_inliers.size()) {
        best_inliers = std::move(inliers);
        best = T;
        const double w = static_cast<double>(best_inliers.size()) / static_cast<double>(n_usable);
        const double miss = 1.0 - w * w * w;
        if (miss <= 1e-12) {
          max_iterations = 0;
        } else {
          const double needed = std::log(1.0 - options_.ransac_confidence) / std::log(miss);
          if (needed < static_cast<double>(max_iterations)) {
            max_iterations = static_cast<int>(std::ceil(needed));
          }
        }
      }
    }
  }
  out.ransac_iterations = it;
  const auto t_ransac = std::chrono::steady_clock::now();
  out.ransac_ms = std::chrono::duration<double, std::milli>(t_ransac - t_start).count();
  // Timings are reported, never used in a decision (determinism).
  const auto stop_refine_clock = [&] {
    out.refine_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t_ransac)
            .count();
  };
  if (static_cast<int>(best_inliers.size()) < options_.min_inliers) return out;

  // Refine on the RANSAC inliers, re-select inliers with the refined pose, refine again.
  out.lm_iterations = Refine(observations, best_inliers, &best);
  std::vector<int> inliers;
  for (int i : usable) {
    if (IsInlier(best, observations[static_cast<size_t>(i)])) inliers.push_back(i);
  }
  if (static_cast<int>(inliers.size()) < options_.min_inliers) return out;
  out.lm_iterations += Refine(observations, inliers, &best);

  // Covariance of the weighted fit: (sum J^T W J)^-1, scaled up when the
  // whitened residuals are larger than the noise model says (never down).
  double sum_sq = 0.0;
  double chi2 = 0.0;
  int rows = 0;
  Matrix6d H = Matrix6d::Zero();
  Eigen::Vector4d r;
  Matrix46d J;
  for (int i : inliers) {
    const StereoObservation& o = observations[static_cast<size_t>(i)];
    if (!ReprojectionResidual(best, o, &r, &J)) continue;
    const Eigen::Matrix4d W = ObservationWeight(best, o);
    H.noalias() += J.transpose() * W * J;
    sum_sq += r.squaredNorm();
    chi2 += r.dot(W * r);
    rows += o.has_right ? 4 : 2;
  }
  if (rows <= 6) return out;
  const Eigen::FullPivLU<Matrix6d> lu(H);
  if (!lu.isInvertible()) return out;
  out.residual_scale = std::sqrt(std::max(chi2 / static_cast<double>(rows - 6), 1.0));
  const Matrix6d covariance = out.residual_scale * out.residual_scale * lu.inverse();
  out.rms_error_px = std::sqrt(sum_sq / static_cast<double>(rows));
  out.spread = Spread(observations, inliers);
  double inflation = 1.0;
  const auto count = static_cast<int>(inliers.size());
  if (count < options_.good_inliers) {
    inflation *= static_cast<double>(options_.good_inliers) / static_cast<double>(count);
  }
  if (out.spread < options_.good_spread) {
    inflation *= options_.good_spread / std::max(out.spread, 1e-3);
  }
  out.inflation = inflation;
  out.covariance = inflation * options_.covariance_scale * covariance;
  out.covariance = 0.5 * (out.covariance + out.covariance.transpose()).eval();
  out.T_cur_ref = best;
  out.inliers = std::move(inliers);
  out.valid = true;
  stop_refine_clock();
  return out;
}

RelativePoseMeasurement ToBodyRelativePose(const Eigen::Isometry3d& T_cur_ref,
                                           const Matrix6d& covariance_cam,
                                           const Eigen::Isometry3d& T_body_cam0rect) {
  // T_est = Exp(xi) T_cur_ref  =>  T_ref_cur,est = T_ref_cur Exp(-xi) (same
  // covariance); conjugating with X = T_body_cam0rect gives the body-side
  // perturbation Ad(X) (-xi) of T_bodyref_bodycur, whose translation noise is
  // R_bodyref_bodycur * rho to first order.
  const Eigen::Isometry3d& X = T_body_cam0rect;
  const Eigen::Isometry3d B = X * T_cur_ref.inverse() * X.inverse();
  const Matrix6d ad = Adjoint(X);
  Matrix6d G = Matrix6d::Identity();
  G.topLeftCorner<3, 3>() = B.linear();
  const Matrix6d M = G * ad;
  RelativePoseMeasurement m;
  m.p_from_to = B.translation();
  m.q_from_to = Eigen::Quaterniond(B.linear()).normalized();
  m.covariance = M * covariance_cam * M.transpose();
  m.covariance = 0.5 * (m.covariance + m.covariance.transpose()).eval();
  return m;
}

}  // namespace rover::estimator::vo
