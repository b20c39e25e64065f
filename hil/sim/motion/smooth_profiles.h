#ifndef ROVER_HIL_SIM_MOTION_SMOOTH_PROFILES_H_
#define ROVER_HIL_SIM_MOTION_SMOOTH_PROFILES_H_

// The smooth building blocks of the rover trajectory:
//
//  * the septic smoothstep S(x) = 35x^4 - 84x^5 + 70x^6 - 20x^7, which goes
//    from 0 to 1 on [0, 1] with its first three derivatives zero at both ends.
//    A speed ramp or a heading change shaped by it therefore joins constant
//    pieces with continuous velocity, acceleration and jerk;
//  * a uniform quintic B-spline of scalar samples: C^4 everywhere by
//    construction, and a mild low-pass of the samples (its kernel spans six
//    knots), which is what the terrain-contact profile needs.

#include <vector>

namespace rover::sim {

/// Septic smoothstep and its derivatives; x is clamped to [0, 1].
struct SepticStep {
  /// Peak of S'(x), at x = 1/2.
  static constexpr double kMaxFirstDerivative = 2.1875;
  /// Peak of |S''(x)| (at x ~ 0.2261 and 0.7739).
  static constexpr double kMaxSecondDerivative = 7.5132;

  static double Value(double x);
  static double D1(double x);
  static double D2(double x);
  static double D3(double x);
  /// Integral of S from 0 to x; Integral(1) = 1/2.
  static double Integral(double x);
};

/// Value and first two derivatives of a scalar function.
struct Jet2 {
  double value = 0.0;
  double d1 = 0.0;
  double d2 = 0.0;
};

/// Uniform quintic B-spline over u in [0, (n - 1) * spacing] whose control
/// point i sits at u = i * spacing. Outside the sample range the first and
/// last control points are repeated, so the spline settles to a constant.
/// Control points are the samples themselves (no interpolation solve): the
/// spline approximates them with the smoothing kernel
/// (1, 26, 66, 26, 1) / 120 at the knots.
class QuinticBSpline {
 public:
  QuinticBSpline() = default;
  /// `samples` must hold at least one value; spacing_m must be positive.
  QuinticBSpline(std::vector<double> samples, double spacing);

  /// Value and first two derivatives with respect to u at u.
  Jet2 Evaluate(double u) const;
  double spacing() const { return spacing_; }
  const std::vector<double>& samples() const { return samples_; }

 private:
  double Control(long i) const;

  std::vector<double> samples_;
  double spacing_ = 1.0;
};

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_MOTION_SMOOTH_PROFILES_H_
