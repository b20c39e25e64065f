#include "core/calib/validation.h"

#include <Eigen/LU>
#include <charconv>
#include <cmath>

namespace rover::calib {

std::optional<std::string> RigidTransformProblem(const Eigen::Matrix4d& T) {
  if (!T.allFinite()) return "expected finite numbers, found a NaN or an infinity";
  const Eigen::RowVector4d last = T.row(3);
  if (last != Eigen::RowVector4d(0.0, 0.0, 0.0, 1.0)) {
    return "expected the last row 0 0 0 1, found " + NumberText(last(0)) + " " +
           NumberText(last(1)) + " " + NumberText(last(2)) + " " + NumberText(last(3));
  }
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  const double error = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!(error <= kRotationTolerance)) {
    return "expected an orthonormal rotation part (|R^T R - I| <= " +
           NumberText(kRotationTolerance) + "), found |R^T R - I| = " + NumberText(error);
  }
  const double det = R.determinant();
  if (!(det > 0.0)) {
    return "expected a proper rotation (det R = +1), found det R = " + NumberText(det) +
           " (a reflection)";
  }
  return std::nullopt;
}

std::string NumberText(double value) {
  // 32 characters hold the longest shortest form ("-2.2250738585072014e-308").
  char text[32];
  const std::to_chars_result r = std::to_chars(text, text + sizeof(text), value);
  return std::string(text, r.ptr);
}

}  // namespace rover::calib
