#ifndef ROVER_MAPPING_GRAPH_GRAPH_KEY_H_
#define ROVER_MAPPING_GRAPH_GRAPH_KEY_H_

// Robot-namespaced names of the rover graph's variables: submap origins
// s^r_i, sparse robot poses x^r_i and (robot-independent) landmarks l_i.

#include <compare>
#include <cstdint>
#include <string>

namespace rover::mapping {

struct GraphKey {
  enum class Type : char { kOrigin = 's', kPose = 'x', kLandmark = 'l' };
  Type type = Type::kOrigin;
  int robot = 0;      ///< Robot id; always 0 for landmarks.
  int64_t index = 0;  ///< Submap index, pose index (e.g. a timestamp) or landmark id.

  static GraphKey Origin(int robot, int64_t submap) { return {Type::kOrigin, robot, submap}; }
  static GraphKey Pose(int robot, int64_t pose) { return {Type::kPose, robot, pose}; }
  static GraphKey Landmark(int64_t id) { return {Type::kLandmark, 0, id}; }

  /// "s1_3" (origin 3 of robot 1), "x0_17", "l4".
  std::string ToString() const {
    std::string s(1, static_cast<char>(type));
    if (type != Type::kLandmark) s += std::to_string(robot) + "_";
    return s + std::to_string(index);
  }

  auto operator<=>(const GraphKey&) const = default;
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_GRAPH_GRAPH_KEY_H_
