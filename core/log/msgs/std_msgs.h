#ifndef ROVER_CORE_LOG_MSGS_STD_MSGS_H_
#define ROVER_CORE_LOG_MSGS_STD_MSGS_H_

// std_msgs/msg/Header.

#include <string_view>

#include "core/log/cdr/cdr_reader.h"
#include "core/log/cdr/cdr_writer.h"
#include "core/log/msgs/builtin_interfaces.h"
#include "core/log/msgs/inline_string.h"
#include "core/log/msgs/message_traits.h"

namespace rover::log {
namespace std_msgs {

/// std_msgs/msg/Header. The frame id is stored inline (FrameId) so that every
/// stamped message is trivially copyable and serialisable without allocation.
struct Header {
  builtin_interfaces::Time stamp;
  FrameId frame_id;

  friend bool operator==(const Header&, const Header&) = default;
};

void Serialize(const Header& msg, CdrWriter& writer);
/// Fails if frame_id is longer than FrameId::kCapacity or contains NUL.
bool Deserialize(CdrReader& reader, Header* msg);

}  // namespace std_msgs

template <>
struct MessageTraits<std_msgs::Header> {
  static constexpr std::string_view kName = "std_msgs/msg/Header";
  static std::string_view Definition();
};

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_MSGS_STD_MSGS_H_
