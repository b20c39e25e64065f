#ifndef ROVER_CORE_LOG_MSGS_OCTOMAP_MSGS_H_
#define ROVER_CORE_LOG_MSGS_OCTOMAP_MSGS_H_

// octomap_msgs/msg/Octomap: an OctoMap octree as the ROS octomap_msgs package
// carries it, so logs open in tools that know the type (Foxglove shows the
// raw message; octomap_rviz_plugins renders it).

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/log/cdr/cdr_reader.h"
#include "core/log/cdr/cdr_writer.h"
#include "core/log/msgs/message_traits.h"
#include "core/log/msgs/std_msgs.h"

namespace rover::log {
namespace octomap_msgs {

/// octomap_msgs/msg/Octomap. `binary` true: `data` is the body of a .bt
/// stream (occupied/free only, from OcTree::writeBinaryData); false: the full
/// log-odds tree (AbstractOcTree::writeData). `id` names the tree class
/// ("OcTree"). Host-side (vector).
struct Octomap {
  std_msgs::Header header;
  bool binary = true;
  std::string id = "OcTree";
  double resolution = 0.0;  // m, leaf edge
  std::vector<int8_t> data;

  friend bool operator==(const Octomap&, const Octomap&) = default;
};

void Serialize(const Octomap& msg, CdrWriter& writer);
bool Deserialize(CdrReader& reader, Octomap* msg);

}  // namespace octomap_msgs

template <>
struct MessageTraits<octomap_msgs::Octomap> {
  static constexpr std::string_view kName = "octomap_msgs/msg/Octomap";
  static std::string_view Definition();
};

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_MSGS_OCTOMAP_MSGS_H_
