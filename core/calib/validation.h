#ifndef ROVER_CORE_CALIB_VALIDATION_H_
#define ROVER_CORE_CALIB_VALIDATION_H_

// Checks shared by the calibration types: what makes a 4x4 matrix a rigid
// transform, and how a problem names the field it is about.

#include <Eigen/Core>
#include <optional>
#include <string>

namespace rover::calib {

/// A calibration value that is unusable: `field` is its key (a dotted path
/// such as "cameras.cam0.intrinsics" where the type is nested) and `message`
/// says what was expected and what was found.
struct FieldProblem {
  std::string field;
  std::string message;
};

/// Tolerance on |R^T R - I| (largest element) for the rotation part of a
/// rigid transform: loose enough for calibrations published with 9-12
/// digits, tight enough to catch a typo.
inline constexpr double kRotationTolerance = 1e-6;

/// Why `T` is not a rigid transform, or nullopt if it is one: every element
/// finite, the rotation part orthonormal within kRotationTolerance with
/// det R > 0 (no reflection), and the last row exactly 0 0 0 1.
std::optional<std::string> RigidTransformProblem(const Eigen::Matrix4d& T);

/// The shortest text that reads back as exactly `value` (std::to_chars), for
/// files that must round-trip bit for bit and for error messages.
std::string NumberText(double value);

}  // namespace rover::calib

#endif  // ROVER_CORE_CALIB_VALIDATION_H_
