#include "hil/sim/motion/smooth_profiles.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <utility>

namespace rover::sim {
namespace {
double Clamp01(double x) { return std::clamp(x, 0.0, 1.0); }
}  // namespace

double SepticStep::Value(double x) {
  x = Clamp01(x);
  const double x2 = x * x;
  return x2 * x2 * (35.0 + x * (-84.0 + x * (70.0 - 20.0 * x)));
}

double SepticStep::D1(double x) {
  x = Clamp01(x);
  const double y = x * (1.0 - x);
  return 140.0 * y * y * y;
}

double SepticStep::D2(double x) {
  x = Clamp01(x);
  const double y = x * (1.0 - x);
  return 420.0 * y * y * (1.0 - 2.0 * x);
}

double SepticStep::D3(double x) {
  x = Clamp01(x);
  return 420.0 * x * (2.0 + x * (-12.0 + x * (20.0 - 10.0 * x)));
}

double SepticStep::Integral(double x) {
  if (x <= 0.0) return 0.0;
  if (x >= 1.0) return 0.5 + (x - 1.0);
  const double x2 = x * x;
  return x2 * x2 * x * (7.0 + x * (-14.0 + x * (10.0 - 2.5 * x)));
}

QuinticBSpline::QuinticBSpline(std::vector<double> samples, double spacing)
    : samples_(std::move(samples)), spacing_(spacing) {
  assert(!samples_.empty() && spacing_ > 0.0);
}

double QuinticBSpline::Control(long i) const {
  const long last = static_cast<long>(samples_.size()) - 1;
  return samples_[static_cast<std::size_t>(std::clamp(i, 0L, last))];
}

Jet2 QuinticBSpline::Evaluate(double u) const {
  // Segment [j, j + 1) (in knot units) is spanned by controls j-2 .. j+3.
  const double x = u / spacing_;
  const double jf = std::floor(x);
  const double t = x - jf;
  // Far outside the samples every control is the same: the spline is flat.
  const double limit = static_cast<double>(samples_.size()) + 8.0;
  if (jf < -8.0 || jf > limit) return {Control(jf < 0.0 ? 0 : static_cast<long>(limit)), 0, 0};
  const long j = static_cast<long>(jf);
  const double t2 = t * t, t3 = t2 * t, t4 = t3 * t, t5 = t4 * t;
  const double s = 1.0 - t;
  // Uniform quintic basis (times 120) and its first two derivatives in t.
  const double b[6] = {s * s * s * s * s,
                       26.0 - 50.0 * t + 20.0 * t2 + 20.0 * t3 - 20.0 * t4 + 5.0 * t5,
                       66.0 - 60.0 * t2 + 30.0 * t4 - 10.0 * t5,
                       26.0 + 50.0 * t + 20.0 * t2 - 20.0 * t3 - 20.0 * t4 + 10.0 * t5,
                       1.0 + 5.0 * t + 10.0 * t2 + 10.0 * t3 + 5.0 * t4 - 5.0 * t5,
                       t5};
  const double db[6] = {-5.0 * s * s * s * s,
                        -50.0 + 40.0 * t + 60.0 * t2 - 80.0 * t3 + 25.0 * t4,
                        -120.0 * t + 120.0 * t3 - 50.0 * t4,
                        50.0 + 40.0 * t - 60.0 * t2 - 80.0 * t3 + 50.0 * t4,
                        5.0 + 20.0 * t + 30.0 * t2 + 20.0 * t3 - 25.0 * t4,
                        5.0 * t4};
  const double ddb[6] = {20.0 * s * s * s,
                         40.0 + 120.0 * t - 240.0 * t2 + 100.0 * t3,
                         -120.0 + 360.0 * t2 - 200.0 * t3,
                         40.0 - 120.0 * t - 240.0 * t2 + 200.0 * t3,
                         20.0 + 60.0 * t + 60.0 * t2 - 100.0 * t3,
                         20.0 * t3};
  Jet2 out;
  for (int i = 0; i < 6; ++i) {
    const double c = Control(j - 2 + i);
    out.value += c * b[i];
    out.d1 += c * db[i];
    out.d2 += c * ddb[i];
  }
  const double inv = 1.0 / spacing_;
  out.value /= 120.0;
  out.d1 *= inv / 120.0;
  out.d2 *= inv * inv / 120.0;
  return out;
}

}  // namespace rover::sim
