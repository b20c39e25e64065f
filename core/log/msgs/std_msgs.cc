#include "core/log/msgs/std_msgs.h"

#include "core/log/msgs/definitions.h"
#include "core/log/msgs/field_io.h"

namespace rover::log {
namespace std_msgs {

void Serialize(const Header& msg, CdrWriter& writer) {
  Serialize(msg.stamp, writer);
  writer.WriteString(msg.frame_id.view());
}

bool Deserialize(CdrReader& reader, Header* msg) {
  return reader.ReadNested("stamp", &msg->stamp) &&
         internal::ReadInlineString(reader, "frame_id", &msg->frame_id);
}

}  // namespace std_msgs

std::string_view MessageTraits<std_msgs::Header>::Definition() {
  return internal::CachedDefinition<std_msgs::Header>();
}

}  // namespace rover::log
