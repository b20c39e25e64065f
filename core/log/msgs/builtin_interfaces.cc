#include "core/log/msgs/builtin_interfaces.h"

#include "core/log/msgs/definitions.h"

namespace rover::log {
namespace builtin_interfaces {

void Serialize(const Time& msg, CdrWriter& writer) {
  writer.WriteI32(msg.sec);
  writer.WriteU32(msg.nanosec);
}

bool Deserialize(CdrReader& reader, Time* msg) {
  return reader.ReadI32("sec", &msg->sec) && reader.ReadU32("nanosec", &msg->nanosec);
}

}  // namespace builtin_interfaces

std::string_view MessageTraits<builtin_interfaces::Time>::Definition() {
  return internal::CachedDefinition<builtin_interfaces::Time>();
}

}  // namespace rover::log
