#ifndef ROVER_CORE_LOG_MSGS_TF2_MSGS_H_
#define ROVER_CORE_LOG_MSGS_TF2_MSGS_H_

// tf2_msgs/msg/TFMessage (the /tf and /tf_static payload).

#include <string_view>
#include <vector>

#include "core/log/cdr/cdr_reader.h"
#include "core/log/cdr/cdr_writer.h"
#include "core/log/msgs/geometry_msgs.h"
#include "core/log/msgs/message_traits.h"

namespace rover::log {
namespace tf2_msgs {

/// tf2_msgs/msg/TFMessage. Host-side (the list is a std::vector); the
/// real-time path logs individual geometry_msgs::TransformStamped instead.
struct TFMessage {
  std::vector<geometry_msgs::TransformStamped> transforms;

  friend bool operator==(const TFMessage&, const TFMessage&) = default;
};

void Serialize(const TFMessage& msg, CdrWriter& writer);
bool Deserialize(CdrReader& reader, TFMessage* msg);

}  // namespace tf2_msgs

template <>
struct MessageTraits<tf2_msgs::TFMessage> {
  static constexpr std::string_view kName = "tf2_msgs/msg/TFMessage";
  static std::string_view Definition();
};

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_MSGS_TF2_MSGS_H_
