#ifndef ROVER_HIL_SIM_SCENARIO_TEAM_ROVERS_H_
#define ROVER_HIL_SIM_SCENARIO_TEAM_ROVERS_H_

// The rovers of a (team) scenario, shared by everything that simulates one
// of them: `rover-sim generate` records every rover, `roverd-sim --rover K`
// runs rover K live, `rover-sim map` scores rover K's mission. Rover 0
// drives scenario.route and is the world's "rover_a"; rover k > 0 drives
// scenario.other_rover_routes[k - 1] and is the world's k-th other rover
// ("rover_b", ...).

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "hil/sim/motion/rover_trajectory.h"
#include "hil/sim/scenario/scenario.h"
#include "hil/sim/world/world.h"

namespace rover::sim {

/// The rovers of a scenario in one world: their trajectories (world frame),
/// names, and which rover each moving tag carrier of the world belongs to.
struct TeamRovers {
  /// One per rover: [0] drives scenario.route, [k] other_rover_routes[k - 1].
  std::vector<RoverTrajectory> trajectories;
  /// carrier_rover[j]: the rover that the world's j-th moving tag carrier
  /// (in world.carriers order, static carriers skipped) belongs to.
  std::vector<std::size_t> carrier_rover;
  /// One per rover: its carrier's name ("rover_a", "rover_b", ...); rover 0
  /// is "rover_a" even when it carries no tags (a scenario without other
  /// rovers).
  std::vector<std::string> names;

  /// How many rovers the scenario has (1 + its other rovers).
  std::size_t size() const { return trajectories.size(); }

  /// The trajectory of every moving tag carrier, in world order, for
  /// MovingCarrierPoses and SimStereoCameraDriver. The pointers point into
  /// `trajectories`: valid while this object lives and is not modified.
  std::vector<const RoverTrajectory*> CarrierTrajectories() const;

  /// The index (into CarrierTrajectories()) of rover `self`'s own carrier,
  /// which its camera must not see; kNoHiddenCarrier when it carries no tags.
  std::size_t HiddenCarrier(std::size_t self) const;
};

/// The rovers of `scenario` in `world` (generated from scenario.world).
/// Throws std::invalid_argument naming a moving carrier of the world that
/// has no route, or an other rover without a carrier.
TeamRovers MakeTeamRovers(const Scenario& scenario, const World& world);

/// How many rovers `scenario` has: 1 (its route) + its other rovers.
std::size_t RoverCount(const Scenario& scenario);

/// Throws std::invalid_argument unless `rover` is a rover of `scenario`,
/// naming the scenario and how many rovers it has.
void CheckRoverIndex(const Scenario& scenario, std::size_t rover);

/// The IMU noise seed of `rover` under the user seed `seed`, as every
/// simulation of that rover seeds it (datasets and live missions alike):
/// scenario.imu.seed ^ (seed * 0x9E3779B97F4A7C15) ^ (rover * 0xC2B2AE3D27D4EB4F).
/// Rover 0's is independent of how many rovers the scenario has.
uint64_t RoverImuSeed(const Scenario& scenario, uint64_t seed, std::size_t rover);

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_SCENARIO_TEAM_ROVERS_H_
