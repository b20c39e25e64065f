#ifndef ROVER_CORE_LOG_MSGS_ALL_MSGS_H_
#define ROVER_CORE_LOG_MSGS_ALL_MSGS_H_

// Umbrella header for every logged message type, plus a runtime list of their
// schemas (for tools that register or print all of them).

#include <span>
#include <string_view>

#include "core/log/msgs/builtin_interfaces.h"
#include "core/log/msgs/diagnostic_msgs.h"
#include "core/log/msgs/estimator_msgs.h"
#include "core/log/msgs/geometry_msgs.h"
#include "core/log/msgs/inline_string.h"
#include "core/log/msgs/message_traits.h"
#include "core/log/msgs/nav_msgs.h"
#include "core/log/msgs/octomap_msgs.h"
#include "core/log/msgs/rover_msgs.h"
#include "core/log/msgs/sensor_msgs.h"
#include "core/log/msgs/std_msgs.h"
#include "core/log/msgs/tf2_msgs.h"

namespace rover::log {

/// A registered message type's MessageTraits, erased.
struct MessageSchema {
  std::string_view name;             // e.g. "sensor_msgs/msg/Imu"
  std::string_view (*definition)();  // Full ros2msg text.
};

/// Every type with a MessageTraits specialisation, in a fixed order.
std::span<const MessageSchema> AllMessageSchemas();

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_MSGS_ALL_MSGS_H_
