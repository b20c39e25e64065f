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

bool Deserialize(CdrReader& reader, Odometry* msg) {
  return reader.ReadNested("header", &msg->header) &&
         internal::ReadInlineString(reader, "child_frame_id", &msg->child_frame_id) &&
         reader.ReadNested("pose", &msg->pose) && reader.ReadNested("twist", &msg->twist);
}

}  // namespace nav_msgs

std::string_view MessageTraits<nav_msgs::Odometry>::Definition() {
  return internal::CachedDefinition<nav_msgs::Odometry>();
}

}  // namespace rover::log
