#ifndef ROVER_CORE_LOG_MSGS_NAV_MSGS_H_
#define ROVER_CORE_LOG_MSGS_NAV_MSGS_H_

// nav_msgs/msg/Odometry.

#include <string_view>

#include "core/log/cdr/cdr_reader.h"
#include "core/log/cdr/cdr_writer.h"
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

void Serialize(const Odometry& msg, CdrWriter& writer);
/// Fails if a frame id exceeds FrameId::kCapacity.
bool Deserialize(CdrReader& reader, Odometry* msg);

}  // namespace nav_msgs

template <>
struct MessageTraits<nav_msgs::Odometry> {
  static constexpr std::string_view kName = "nav_msgs/msg/Odometry";
  static std::string_view Definition();
};

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_MSGS_NAV_MSGS_H_
