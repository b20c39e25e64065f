#include "hil/sim/world/noise.h"

#include <array>
#include <cmath>

namespace rover::sim {
namespace {

// Rotations with exact rational cosine and sine (Pythagorean triples), so no
// libm call enters the noise; angles spread over 0..360 degrees.
constexpr std::array<std::array<double, 2>, 12> kRotations = {{
    {3.0 / 5.0, 4.0 / 5.0},
    {-5.0 / 13.0, 12.0 / 13.0},
    {8.0 / 17.0, -15.0 / 17.0},
    {-24.0 / 25.0, -7.0 / 25.0},
    {20.0 / 29.0, 21.0 / 29.0},
    {-35.0 / 37.0, 12.0 / 37.0},
    {9.0 / 41.0, -40.0 / 41.0},
    {-28.0 / 53.0, -45.0 / 53.0},
    {60.0 / 61.0, 11.0 / 61.0},
    {-33.0 / 65.0, 56.0 / 65.0},
    {63.0 / 65.0, -16.0 / 65.0},
    {-48.0 / 73.0, -55.0 / 73.0},
}};

}  // namespace

FractalNoise::FractalNoise(uint64_t seed, uint64_t layer,
                           std::initializer_list<NoiseOctave> octaves) {
  const uint64_t layer_seed = HashCombine(seed, layer);
  uint64_t index = 0;
  for (const NoiseOctave& octave : octaves) {
    const uint64_t h = HashCombine(layer_seed, index);
    const auto& rotation = kRotations[(h >> 8) % kRotations.size()];
    Octave o;
    o.cos = rotation[0];
    o.sin = rotation[1];
    o.inv_wavelength = 1.0 / octave.wavelength_m;
    // Offsets keep lattice coordinates well inside int64 and away from the
    // origin, where all octaves would otherwise share a lattice point.
    o.offset_u = 1024.0 * BitsToUnit(MixBits(h + 1));
    o.offset_v = 1024.0 * BitsToUnit(MixBits(h + 2));
    o.amplitude = octave.amplitude;
    o.salt = MixBits(h + 3);
    octaves_.push_back(o);
    ++index;
  }
}

double FractalNoise::Bound() const {
  double sum = 0.0;
  for (const Octave& o : octaves_) {
    sum += std::abs(o.amplitude);
  }
  return 0.7072 * sum;
}

}  // namespace rover::sim
