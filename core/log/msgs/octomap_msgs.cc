#include "core/log/msgs/octomap_msgs.h"

#include "core/log/msgs/definitions.h"

namespace rover::log {
namespace octomap_msgs {

void Serialize(const Octomap& msg, CdrWriter& writer) {
  Serialize(msg.header, writer);
  writer.WriteBool(msg.binary);
  writer.WriteString(msg.id);
  writer.WriteF64(msg.resolution);
  writer.WriteSequenceSize(msg.data.size());
  for (const int8_t octet : msg.data) writer.WriteI8(octet);
}

bool Deserialize(CdrReader& reader, Octomap* msg) {
  std::vector<uint8_t> octets;
  if (!reader.ReadNested("header", &msg->header) || !reader.ReadBool("binary", &msg->binary) ||
      !reader.ReadString("id", &msg->id) || !reader.ReadF64("resolution", &msg->resolution) ||
      !reader.ReadU8Sequence("data", &octets)) {
    return false;
  }
  msg->data.assign(octets.begin(), octets.end());  // int8 and uint8 share the octet
  return true;
}

}  // namespace octomap_msgs

std::string_view MessageTraits<octomap_msgs::Octomap>::Definition() {
  return internal::CachedDefinition<octomap_msgs::Octomap>();
}

}  // namespace rover::log
