#ifndef ROVER_HIL_SIM_WORLD_ALBEDO_H_
#define ROVER_HIL_SIM_WORLD_ALBEDO_H_

// The albedo texture of the generated site; a step of World::Generate, kept
// apart because it is the costliest one (26 M samples for the default world).

#include <cstdint>
#include <vector>

#include "hil/sim/world/world.h"

namespace rover::sim {

/// Albedo over a square of options.size_m centred on the origin at options.albedo_resolution_m:
/// lighter and darker regolith patches (5-20 m), blotches (0.5-2 m), pebbles and grain
/// (2-10 cm), dark speckled rocks, a darker crater interior and brighter ejecta around the rim.
/// Deterministic in its inputs.
AlbedoMap GenerateAlbedo(const WorldOptions& options, uint64_t seed, const std::vector<Rock>& rocks,
                         const std::vector<Crater>& craters);

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_WORLD_ALBEDO_H_
