#include "core/log/msgs/nav_msgs.h"

#include "core/log/msgs/definitions.h"
#include "core/log/msgs/field_io.h"

namespace rover::log {
namespace nav_msgs {

void Serialize(const Odometry& msg, CdrWriter& writer) {
  Serialize(msg.header, writer);
  writer.WriteString(msg.child_frame_id.view());
  Serialize(msg.pose, writer);
  Serialize(msg.twist, writer);
}

void Serialize(const MapMetaData& msg, CdrWriter& writer) {
  Serialize(msg.map_load_time, writer);
  writer.WriteF32(msg.resolution);
  writer.WriteU32(msg.width);
  writer.WriteU32(msg.height);
  Serialize(msg.origin, writer);
}

void Serialize(const OccupancyGrid& msg, CdrWriter& writer) {
  Serialize(msg.header, writer);
  Serialize(msg.info, writer);
  writer.WriteSequenceSize(msg.data.size());
  for (const int8_t cell : msg.data) writer.WriteI8(cell);
}

bool Deserialize(CdrReader& reader, Odometry* msg) {
  return reader.ReadNested("header", &msg->header) &&
         internal::ReadInlineString(reader, "child_frame_id", &msg->child_frame_id) &&
         reader.ReadNested("pose", &msg->pose) && reader.ReadNested("twist", &msg->twist);
}

bool Deserialize(CdrReader& reader, MapMetaData* msg) {
  return reader.ReadNested("map_load_time", &msg->map_load_time) &&
         reader.ReadF32("resolution", &msg->resolution) && reader.ReadU32("width", &msg->width) &&
         reader.ReadU32("height", &msg->height) && reader.ReadNested("origin", &msg->origin);
}

bool Deserialize(CdrReader& reader, OccupancyGrid* msg) {
  std::vector<uint8_t> octets;
  if (!reader.ReadNested("header", &msg->header) || !reader.ReadNested("info", &msg->info) ||
      !reader.ReadU8Sequence("data", &octets)) {
    return false;
  }
  msg->data.assign(octets.begin(), octets.end());  // int8 and uint8 share the octet
  return true;
}

}  // namespace nav_msgs

std::string_view MessageTraits<nav_msgs::Odometry>::Definition() {
  return internal::CachedDefinition<nav_msgs::Odometry>();
}

std::string_view MessageTraits<nav_msgs::MapMetaData>::Definition() {
  return internal::CachedDefinition<nav_msgs::MapMetaData>();
}

std::string_view MessageTraits<nav_msgs::OccupancyGrid>::Definition() {
  return internal::CachedDefinition<nav_msgs::OccupancyGrid>();
}

}  // namespace rover::log
