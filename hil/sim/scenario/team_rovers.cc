#include "hil/sim/scenario/team_rovers.h"

#include <stdexcept>

namespace rover::sim {

std::vector<const RoverTrajectory*> TeamRovers::CarrierTrajectories() const {
  std::vector<const RoverTrajectory*> carriers;
  carriers.reserve(carrier_rover.size());
  for (const std::size_t rover : carrier_rover) carriers.push_back(&trajectories[rover]);
  return carriers;
}

std::size_t TeamRovers::HiddenCarrier(std::size_t self) const {
  for (std::size_t j = 0; j < carrier_rover.size(); ++j) {
    if (carrier_rover[j] == self) return j;
  }
  return kNoHiddenCarrier;
}

TeamRovers MakeTeamRovers(const Scenario& scenario, const World& world) {
  TeamRovers team;
  const std::size_t count = RoverCount(scenario);
  team.trajectories.reserve(count);
  team.trajectories.emplace_back(scenario.route, world.terrain);
  for (const Route& route : scenario.other_rover_routes) {
    team.trajectories.emplace_back(route, world.terrain);
  }
  team.names.resize(count);
  team.names[0] = "rover_a";
  // World order of moving carriers: rover_b, rover_c, ..., then rover_a
  // (rover 0) when it carries tags too.
  for (const TagCarrier& carrier : world.carriers) {
    if (carrier.is_static) continue;
    const std::size_t rover = carrier.name == "rover_a" ? 0 : team.carrier_rover.size() + 1;
    if (rover >= count) {
      throw std::invalid_argument("world carrier " + carrier.name + " has no route");
    }
    team.carrier_rover.push_back(rover);
    team.names[rover] = carrier.name;
  }
  for (std::size_t rover = 1; rover < count; ++rover) {
    if (team.names[rover].empty()) {
      throw std::invalid_argument("scenario " + scenario.name + ": other_rovers[" +
                                  std::to_string(rover - 1) +
                                  "] has no tag carrier in the world (world.other_rover_count " +
                                  std::to_string(scenario.world.other_rover_count) + ")");
    }
  }
  return team;
}

std::size_t RoverCount(const Scenario& scenario) { return 1 + scenario.other_rover_routes.size(); }

void CheckRoverIndex(const Scenario& scenario, std::size_t rover) {
  const std::size_t count = RoverCount(scenario);
  if (rover < count) return;
  std::string which = "0 drives its route";
  if (count > 1) which += ", 1.." + std::to_string(count - 1) + " its other_rovers";
  throw std::invalid_argument("rover " + std::to_string(rover) + " is not a rover of scenario " +
                              scenario.name + ": it has " + std::to_string(count) +
                              (count == 1 ? " rover" : " rovers") + " (" + which + ")");
}

uint64_t RoverImuSeed(const Scenario& scenario, uint64_t seed, std::size_t rover) {
  return scenario.imu.seed ^ (seed * 0x9E3779B97F4A7C15ULL) ^
         (static_cast<uint64_t>(rover) * 0xC2B2AE3D27D4EB4FULL);
}

}  // namespace rover::sim
