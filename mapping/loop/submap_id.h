#ifndef ROVER_MAPPING_LOOP_SUBMAP_ID_H_
#define ROVER_MAPPING_LOOP_SUBMAP_ID_H_

// Which submap: robot and the robot's submap index (as the rover graph's
// origin s^robot_index, GraphKey::Origin).

#include <compare>
#include <cstdint>
#include <string>

namespace rover::mapping {

struct SubmapId {
  int robot = 0;
  int64_t index = 0;

  /// "1/3": submap 3 of robot 1.
  std::string ToString() const { return std::to_string(robot) + "/" + std::to_string(index); }

  auto operator<=>(const SubmapId&) const = default;
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_LOOP_SUBMAP_ID_H_
