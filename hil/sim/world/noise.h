#ifndef ROVER_HIL_SIM_WORLD_NOISE_H_
#define ROVER_HIL_SIM_WORLD_NOISE_H_

// Seeded, integer-hash-based randomness for the world generator. Nothing here
// goes through the <random> distributions, whose algorithms are left to the
// standard library: a value depends only on its seed and inputs, so a world
// is the same bytes with any compiler that gives IEEE doubles.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <random>
#include <vector>

namespace rover::sim {

/// MurmurHash3's 64-bit finaliser: every input bit affects every output bit.
constexpr uint64_t MixBits(uint64_t x) {
  x ^= x >> 33;
  x *= 0xff51afd7ed558ccdULL;
  x ^= x >> 33;
  x *= 0xc4ceb9fe1a85ec53ULL;
  x ^= x >> 33;
  return x;
}

/// Folds `value` into `seed`; order matters, so (a, b) and (b, a) differ.
constexpr uint64_t HashCombine(uint64_t seed, uint64_t value) {
  return MixBits(seed ^ (value + 0x9e3779b97f4a7c15ULL + (seed << 6) + (seed >> 2)));
}

/// Hash of a 2-D lattice point under `salt`. Lighter than MixBits (one multiply after the
/// inputs are combined; the compiler shares ix * K and iy * K between neighbouring corners),
/// because noise evaluation spends most of its time here; the high bits are well mixed.
inline uint64_t LatticeHash(int64_t ix, int64_t iy, uint64_t salt) {
  uint64_t h = (static_cast<uint64_t>(ix) * 0x9e3779b97f4a7c15ULL) ^
               (static_cast<uint64_t>(iy) * 0xd1b54a32d192ed03ULL) ^ salt;
  h ^= h >> 32;
  h *= 0xbf58476d1ce4e5b9ULL;
  h ^= h >> 29;
  return h;
}

/// floor() as an integer, without a libm call (x86-64's baseline has no rounding instruction).
inline int64_t FloorToInt(double x) {
  const auto i = static_cast<int64_t>(x);
  return x < static_cast<double>(i) ? i - 1 : i;
}

/// Uniform in [0, 1) from the top 53 bits.
constexpr double BitsToUnit(uint64_t bits) {
  return static_cast<double>(bits >> 11) * (1.0 / 9007199254740992.0);
}

/// Uniform in [-1, 1) from the top 53 bits.
constexpr double BitsToSigned(uint64_t bits) { return 2.0 * BitsToUnit(bits) - 1.0; }

/// 2-D gradient (Perlin) noise with unit lattice spacing, 16 gradient directions picked by a
/// lattice hash and a quintic fade (C2-continuous). Values lie in about [-0.71, 0.71] with mean 0;
/// it is 0 at lattice points.
inline double GradientNoise2(double x, double y, uint64_t salt) {
  // cos/sin of k * 22.5 degrees, written out so no libm call enters the result.
  static constexpr double kC1 = 0.92387953251128674;
  static constexpr double kC2 = 0.70710678118654752;
  static constexpr double kC3 = 0.38268343236508977;
  static constexpr double kGradients[16][2] = {{1, 0},  {kC1, kC3},   {kC2, kC2},   {kC3, kC1},
                                               {0, 1},  {-kC3, kC1},  {-kC2, kC2},  {-kC1, kC3},
                                               {-1, 0}, {-kC1, -kC3}, {-kC2, -kC2}, {-kC3, -kC1},
                                               {0, -1}, {kC3, -kC1},  {kC2, -kC2},  {kC1, -kC3}};
  const int64_t ix = FloorToInt(x);
  const int64_t iy = FloorToInt(y);
  const double tx = x - static_cast<double>(ix);
  const double ty = y - static_cast<double>(iy);
  const auto corner = [salt](int64_t cx, int64_t cy, double dx, double dy) {
    const double* g = kGradients[LatticeHash(cx, cy, salt) >> 60];
    return g[0] * dx + g[1] * dy;
  };
  const double n00 = corner(ix, iy, tx, ty);
  const double n10 = corner(ix + 1, iy, tx - 1.0, ty);
  const double n01 = corner(ix, iy + 1, tx, ty - 1.0);
  const double n11 = corner(ix + 1, iy + 1, tx - 1.0, ty - 1.0);
  const double u = tx * tx * tx * (tx * (tx * 6.0 - 15.0) + 10.0);
  const double v = ty * ty * ty * (ty * (ty * 6.0 - 15.0) + 10.0);
  const double nx0 = n00 + u * (n10 - n00);
  const double nx1 = n01 + u * (n11 - n01);
  return nx0 + v * (nx1 - nx0);
}

/// One octave of a FractalNoise: a wavelength in metres and the amplitude it contributes.
struct NoiseOctave {
  double wavelength_m = 1.0;
  double amplitude = 1.0;
};

/// Sum of gradient-noise octaves (fBm). Each octave has its own hash salt, a random offset and a
/// rotation by an angle with rational sine and cosine, so the lattices of different octaves
/// never line up (which would show as axis-aligned streaks).
class FractalNoise {
 public:
  FractalNoise() = default;
  /// `layer` tells apart independent fields drawn from the same seed.
  FractalNoise(uint64_t seed, uint64_t layer, std::initializer_list<NoiseOctave> octaves);

  double At(double x_m, double y_m) const {
    double sum = 0.0;
    for (const Octave& o : octaves_) {
      const double u = (o.cos * x_m - o.sin * y_m) * o.inv_wavelength + o.offset_u;
      const double v = (o.sin * x_m + o.cos * y_m) * o.inv_wavelength + o.offset_v;
      sum += o.amplitude * GradientNoise2(u, v, o.salt);
    }
    return sum;
  }
  /// Bound on |At|: the sum of the amplitudes times GradientNoise2's bound.
  double Bound() const;

 private:
  struct Octave {
    double cos = 1.0;
    double sin = 0.0;
    double inv_wavelength = 1.0;
    double offset_u = 0.0;
    double offset_v = 0.0;
    double amplitude = 1.0;
    uint64_t salt = 0;
  };
  std::vector<Octave> octaves_;
};

/// Sequential random numbers for placement decisions. std::mt19937_64's raw output sequence is
/// fixed by the standard, and the conversions below are our own, so draws are reproducible
/// everywhere.
class SeededRandom {
 public:
  explicit SeededRandom(uint64_t seed) : engine_(seed) {}
  uint64_t Bits() { return engine_(); }
  /// Uniform in [0, 1).
  double Uniform() { return BitsToUnit(engine_()); }
  /// Uniform in [lo, hi).
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }

 private:
  std::mt19937_64 engine_;
};

/// 0 below edge0, 1 above edge1, Hermite in between.
inline double SmoothStep(double edge0, double edge1, double x) {
  // Multiplying by the inverse lets constant edges fold into one multiply
  // instead of a division per call (this runs per albedo sample).
  const double t = std::clamp((x - edge0) * (1.0 / (edge1 - edge0)), 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_WORLD_NOISE_H_
