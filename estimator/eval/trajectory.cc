#include "estimator/eval/trajectory.h"

#include <cmath>
#include <limits>
#include <sstream>

#include "estimator/eval/eval_error.h"

namespace rover::eval {
namespace {

std::string Number(double value) {
  std::ostringstream out;
  out.precision(17);
  out << value;
  return out.str();
}

}  // namespace

Eigen::Isometry3d PoseSample::T_world_body() const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q_world_body.toRotationMatrix();
  T.translation() = p_world_body;
  return T;
}

Eigen::Quaterniond UnitQuaternion(const Eigen::Quaterniond& q) {
  const double norm = q.norm();
  if (std::abs(norm - 1.0) <= 4.0 * std::numeric_limits<double>::epsilon()) return q;
  return q.normalized();
}

std::string CheckPoseSample(const PoseSample& sample) {
  if (!sample.p_world_body.allFinite()) {
    return "expected a finite position, found (" + Number(sample.p_world_body.x()) + ", " +
           Number(sample.p_world_body.y()) + ", " + Number(sample.p_world_body.z()) + ")";
  }
  if (!sample.q_world_body.coeffs().allFinite()) {
    return "expected a finite quaternion, found a NaN or infinite coefficient";
  }
  const double norm = sample.q_world_body.norm();
  if (std::abs(norm - 1.0) > 1e-6) {
    return "expected a unit quaternion, found norm " + Number(norm);
  }
  if (sample.v_world_body_m_s && !sample.v_world_body_m_s->allFinite()) {
    return "expected a finite velocity, found a NaN or infinite component";
  }
  if (sample.covariance) {
    const Matrix6d& P = *sample.covariance;
    if (!P.allFinite()) return "expected a finite covariance, found a NaN or infinite entry";
    const double asymmetry = (P - P.transpose()).cwiseAbs().maxCoeff();
    if (asymmetry > 1e-9 * std::max(1.0, P.cwiseAbs().maxCoeff())) {
      return "expected a symmetric covariance, found an asymmetry of " + Number(asymmetry);
    }
    if (P.diagonal().minCoeff() < 0.0) {
      return "expected a non-negative covariance diagonal, found " +
             Number(P.diagonal().minCoeff());
    }
  }
  return {};
}

Trajectory::Trajectory(std::vector<PoseSample> samples, std::string source)
    : samples_(std::move(samples)), source_(std::move(source)) {}

bool Trajectory::HasCovariance() const {
  for (const PoseSample& s : samples_) {
    if (s.covariance) return true;
  }
  return false;
}

Duration Trajectory::Span() const {
  if (samples_.size() < 2) return Duration::Zero();
  return samples_.back().stamp - samples_.front().stamp;
}

void Trajectory::Validate() const {
  const std::string prefix = source_.empty() ? std::string("trajectory") : source_;
  for (std::size_t i = 0; i < samples_.size(); ++i) {
    const PoseSample& s = samples_[i];
    const std::string where =
        prefix + ": sample " + std::to_string(i) + " (t = " + s.stamp.ToString() + "): ";
    const std::string problem = CheckPoseSample(s);
    if (!problem.empty()) throw EvalError(where + problem);
    if (i > 0 && s.stamp <= samples_[i - 1].stamp) {
      throw EvalError(where + "expected stamps to increase, found " + s.stamp.ToString() +
                      " after " + samples_[i - 1].stamp.ToString());
    }
  }
}

Trajectory Trajectory::Transformed(const Eigen::Isometry3d& T_new_world, double scale) const {
  const Eigen::Matrix3d R = T_new_world.linear();
  const Eigen::Quaterniond q(R);
  Trajectory out;
  out.source_ = source_;
  out.samples_.reserve(samples_.size());
  for (const PoseSample& s : samples_) {
    PoseSample t = s;
    t.p_world_body = scale * (R * s.p_world_body) + T_new_world.translation();
    t.q_world_body = (q * s.q_world_body).normalized();
    if (s.v_world_body_m_s) t.v_world_body_m_s = scale * (R * *s.v_world_body_m_s);
    if (s.covariance) {
      Matrix6d J = Matrix6d::Identity();
      J.topLeftCorner<3, 3>() = scale * R;
      t.covariance = J * *s.covariance * J.transpose();
    }
    out.samples_.push_back(t);
  }
  return out;
}

}  // namespace rover::eval
