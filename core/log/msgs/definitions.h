#ifndef ROVER_CORE_LOG_MSGS_DEFINITIONS_H_
#define ROVER_CORE_LOG_MSGS_DEFINITIONS_H_

// ros2msg schema texts of the logged message types (internal to core/log/msgs;
// use MessageTraits<T>::Definition()).

#include <string>
#include <string_view>
#include <vector>

#include "core/log/msgs/message_traits.h"

namespace rover::log::internal {

/// The .msg text of one type, without its dependencies. `type` may be given as
/// "pkg/msg/Type" or "pkg/Type". Returns an empty view for unknown types.
std::string_view OwnDefinition(std::string_view type);

/// The complex types referenced by the fields of `type`'s own definition, in
/// field order, normalised to "pkg/Type" (a bare "Type" resolves to `type`'s
/// package, as in ROS). Duplicates are kept.
std::vector<std::string> DirectDependencies(std::string_view type);

/// The full schema text MCAP's ros2 profile expects: `type`'s own definition,
/// then every transitive dependency exactly once (depth-first, in field order),
/// each preceded by a line of 80 '=' and a line "MSG: pkg/Type".
std::string ComposeDefinition(std::string_view type);

/// ComposeDefinition(MessageTraits<T>::kName), built on first use (thread-safe)
/// and kept for the life of the process.
template <typename T>
std::string_view CachedDefinition() {
  static const std::string text = ComposeDefinition(MessageTraits<T>::kName);
  return text;
}

}  // namespace rover::log::internal

#endif  // ROVER_CORE_LOG_MSGS_DEFINITIONS_H_
