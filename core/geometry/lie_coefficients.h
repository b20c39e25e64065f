#ifndef ROVER_CORE_GEOMETRY_LIE_COEFFICIENTS_H_
#define ROVER_CORE_GEOMETRY_LIE_COEFFICIENTS_H_

// Scalar coefficients of the SO(3)/SE(3) closed forms, as functions of the
// rotation angle theta >= 0. Internal to core/geometry; not part of the API.
//
// Every coefficient is a ratio whose numerator and denominator both vanish at
// theta = 0, and most of them suffer catastrophic cancellation for small theta
// (e.g. theta - sin(theta) ~ theta^3 / 6 loses about 2*log10(1/theta) digits).
// Below kSeriesThreshold we therefore evaluate the Maclaurin series, truncated
// after the theta^8 term: at theta = 0.1 the first dropped term is below
// 1e-17 relative for every coefficient. Above the threshold the closed forms
// still lose digits (up to ~1e-10 relative for SE3QCoefficient3 at 0.1), but
// each coefficient multiplies a product of skew matrices that shrinks at least
// as fast as the cancellation grows, so the absolute error of the resulting
// matrices stays at the 1e-15 level.

#include <cmath>

namespace rover::geometry_internal {

inline constexpr double kSeriesThreshold = 0.1;

/// Evaluates c0 + c1 x + c2 x^2 + c3 x^3 + c4 x^4 (Horner), x = theta^2.
inline double Series(double x, double c0, double c1, double c2, double c3, double c4) {
  return c0 + x * (c1 + x * (c2 + x * (c3 + x * c4)));
}

/// sin(theta) / theta.
inline double SinOverTheta(double theta) {
  if (theta < kSeriesThreshold) {
    return Series(theta * theta, 1.0, -1.0 / 6.0, 1.0 / 120.0, -1.0 / 5040.0, 1.0 / 362880.0);
  }
  return std::sin(theta) / theta;
}

/// (1 - cos(theta)) / theta^2. The half-angle form 2 sin^2(theta/2) / theta^2
/// is free of cancellation, but the series is still needed at theta = 0.
inline double OneMinusCosOverTheta2(double theta) {
  if (theta < kSeriesThreshold) {
    return Series(theta * theta, 1.0 / 2.0, -1.0 / 24.0, 1.0 / 720.0, -1.0 / 40320.0,
                  1.0 / 3628800.0);
  }
  const double s = std::sin(0.5 * theta) / theta;
  return 2.0 * s * s;
}

/// (theta - sin(theta)) / theta^3.
inline double ThetaMinusSinOverTheta3(double theta) {
  if (theta < kSeriesThreshold) {
    return Series(theta * theta, 1.0 / 6.0, -1.0 / 120.0, 1.0 / 5040.0, -1.0 / 362880.0,
                  1.0 / 39916800.0);
  }
  return (theta - std::sin(theta)) / (theta * theta * theta);
}

/// 1/theta^2 - (1 + cos(theta)) / (2 theta sin(theta)), the K^2 coefficient of
/// the inverse SO(3) Jacobians. (1 + cos) / sin is rewritten as cot(theta/2)
/// so that the expression stays finite at theta = pi (where it is 1/pi^2); it
/// is singular only at theta = 2 pi, where the Jacobians are not invertible.
inline double InverseJacobianCoefficient(double theta) {
  if (theta < kSeriesThreshold) {
    return Series(theta * theta, 1.0 / 12.0, 1.0 / 720.0, 1.0 / 30240.0, 1.0 / 1209600.0,
                  1.0 / 47900160.0);
  }
  const double half = 0.5 * theta;
  return 1.0 / (theta * theta) - std::cos(half) / (2.0 * theta * std::sin(half));
}

/// (theta^2 + 2 cos(theta) - 2) / (2 theta^4), used by the SE(3) Q block.
inline double SE3QCoefficient2(double theta) {
  if (theta < kSeriesThreshold) {
    return Series(theta * theta, 1.0 / 24.0, -1.0 / 720.0, 1.0 / 40320.0, -1.0 / 3628800.0,
                  1.0 / 479001600.0);
  }
  const double theta2 = theta * theta;
  return (theta2 + 2.0 * std::cos(theta) - 2.0) / (2.0 * theta2 * theta2);
}

/// (2 theta - 3 sin(theta) + theta cos(theta)) / (2 theta^5), used by the SE(3)
/// Q block.
inline double SE3QCoefficient3(double theta) {
  if (theta < kSeriesThreshold) {
    return Series(theta * theta, 1.0 / 120.0, -1.0 / 2520.0, 1.0 / 120960.0, -1.0 / 9979200.0,
                  1.0 / 1245404160.0);
  }
  const double theta2 = theta * theta;
  return (2.0 * theta - 3.0 * std::sin(theta) + theta * std::cos(theta)) /
         (2.0 * theta2 * theta2 * theta);
}

/// sin(theta/2) / theta, the vector-part scale of the unit quaternion Exp.
inline double SinHalfOverTheta(double theta) {
  if (theta < kSeriesThreshold) {
    return Series(theta * theta, 1.0 / 2.0, -1.0 / 48.0, 1.0 / 3840.0, -1.0 / 645120.0,
                  1.0 / 185794560.0);
  }
  return std::sin(0.5 * theta) / theta;
}

}  // namespace rover::geometry_internal

#endif  // ROVER_CORE_GEOMETRY_LIE_COEFFICIENTS_H_
