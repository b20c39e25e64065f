#ifndef ROVER_HIL_SIM_SEED_H_
#define ROVER_HIL_SIM_SEED_H_

// Seed derivation shared by the simulator's random streams: every stream
// (IMU noise, wheel slip, one per rover) gets its own seed from one user
// seed, so turning one source off or adding a rover never shifts another.

#include <cstdint>

namespace rover::sim {

/// SplitMix64's finaliser: consecutive inputs give uncorrelated outputs.
constexpr uint64_t SplitMix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

/// The seed of stream `stream` under user seed `seed`.
constexpr uint64_t StreamSeed(uint64_t seed, uint64_t stream) {
  return SplitMix64(SplitMix64(seed) ^ stream);
}

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_SEED_H_
