#ifndef ROVER_CORE_LOG_MSGS_NAV_MSGS_H_
#define ROVER_CORE_LOG_MSGS_NAV_MSGS_H_

// nav_msgs/msg/Odometry, MapMetaData and OccupancyGrid.

#include <cstdint>
#include <string_view>
#include <vector>

#include "core/log/cdr/cdr_reader.h"
#include "core/log/cdr/cdr_writer.h"
#include "core/log/msgs/builtin_interfaces.h"
#include "core/log/msgs/geometry_msgs.h"
#include "core/log/msgs/inline_string.h"
#include "core/log/msgs/message_traits.h"
#include "core/log/msgs/std_msgs.h"

namespace rover::log {
namespace nav_msgs {

/// nav_msgs/msg/Odometry: `pose` is expressed in header.frame_id, `twist` in
/// child_frame_id. Trivially copyable; serialises without allocation.
struct Odometry {
  std_msgs::Header header;
  FrameId child_frame_id;
  geometry_msgs::PoseWithCovariance pose;
  geometry_msgs::TwistWithCovariance twist;

  friend bool operator==(const Odometry&, const Odometry&) = default;
};

/// nav_msgs/msg/MapMetaData: the grid's geometry. Cell (0, 0) is the lower
/// corner at `origin`; cells are `resolution` metres square.
struct MapMetaData {
  builtin_interfaces::Time map_load_time;
  float resolution = 0.0f;  // m per cell
  uint32_t width = 0;       // cells along x
  uint32_t height = 0;      // cells along y
  geometry_msgs::Pose origin;

  friend bool operator==(const MapMetaData&, const MapMetaData&) = default;
};

/// nav_msgs/msg/OccupancyGrid: row-major cells (x fastest), each 0..100 or
/// -1 for unknown. Host-side (vector).
struct OccupancyGrid {
  std_msgs::Header header;
  MapMetaData info;
  std::vector<int8_t> data;

  friend bool operator==(const OccupancyGrid&, const OccupancyGrid&) = default;
};

void Serialize(const Odometry& msg, CdrWriter& writer);
void Serialize(const MapMetaData& msg, CdrWriter& writer);
void Serialize(const OccupancyGrid& msg, CdrWriter& writer);
/// Fails if a frame id exceeds FrameId::kCapacity.
bool Deserialize(CdrReader& reader, Odometry* msg);
bool Deserialize(CdrReader& reader, MapMetaData* msg);
bool Deserialize(CdrReader& reader, OccupancyGrid* msg);

}  // namespace nav_msgs

template <>
struct MessageTraits<nav_msgs::Odometry> {
  static constexpr std::string_view kName = "nav_msgs/msg/Odometry";
  static std::string_view Definition();
};

template <>
struct MessageTraits<nav_msgs::MapMetaData> {
  static constexpr std::string_view kName = "nav_msgs/msg/MapMetaData";
  static std::string_view Definition();
};

template <>
struct MessageTraits<nav_msgs::OccupancyGrid> {
  static constexpr std::string_view kName = "nav_msgs/msg/OccupancyGrid";
  static std::string_view Definition();
};

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_MSGS_NAV_MSGS_H_
