#ifndef ROVER_CORE_LOG_MSGS_MESSAGE_TRAITS_H_
#define ROVER_CORE_LOG_MSGS_MESSAGE_TRAITS_H_

// Compile-time registry of the ROS 2 message types the flight log writes, and
// generic serialisation entry points over it.
//
// Every message header (std_msgs.h, sensor_msgs.h, ...) specialises
// MessageTraits for its types:
//
//   template <> struct MessageTraits<sensor_msgs::Imu> {
//     static constexpr std::string_view kName = "sensor_msgs/msg/Imu";
//     static std::string_view Definition();  // full ros2msg schema text
//   };
//
// and declares `void Serialize(const T&, CdrWriter&)` and
// `bool Deserialize(CdrReader&, T*)` in the type's namespace (found by ADL).
// Registering an MCAP schema is then
//
//   writer.AddSchema(MessageTraits<T>::kName, kRos2MsgSchemaEncoding,
//                    MessageTraits<T>::Definition());

#include <concepts>
#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/log/cdr/cdr_reader.h"
#include "core/log/cdr/cdr_writer.h"

namespace rover::log {

/// MCAP schema encoding of the definitions returned by MessageTraits.
inline constexpr std::string_view kRos2MsgSchemaEncoding = "ros2msg";
/// MCAP message encoding of the bytes produced by Serialize.
inline constexpr std::string_view kCdrMessageEncoding = "cdr";

/// Specialised per message type; the primary template is deliberately left
/// undefined so that logging an unregistered type does not compile.
template <typename T>
struct MessageTraits;

/// A registered message type with CDR serialisation.
template <typename T>
concept RosMessage = requires(const T& msg, CdrWriter& writer, CdrReader& reader, T* out) {
  { MessageTraits<T>::kName } -> std::convertible_to<std::string_view>;
  { MessageTraits<T>::Definition() } -> std::same_as<std::string_view>;
  Serialize(msg, writer);
  { Deserialize(reader, out) } -> std::same_as<bool>;
};

/// Serialises `msg` (encapsulation header included) into `buffer` without
/// allocating. Returns the number of bytes written, or 0 if `buffer` is too
/// small (use SerializedSize to size it).
template <RosMessage T>
size_t SerializeMessage(const T& msg, std::span<std::byte> buffer) {
  CdrWriter writer(buffer);
  Serialize(msg, writer);
  return writer.ok() ? writer.size() : 0;
}

/// Exact number of bytes SerializeMessage needs for `msg`. Does not allocate.
template <RosMessage T>
size_t SerializedSize(const T& msg) {
  CdrWriter writer(std::span<std::byte>{});
  Serialize(msg, writer);
  return writer.required_size();
}

/// Serialises `msg` into a new vector (host use; allocates).
template <RosMessage T>
std::vector<std::byte> SerializeMessage(const T& msg) {
  std::vector<std::byte> bytes;
  CdrWriter writer(&bytes);
  Serialize(msg, writer);
  return bytes;
}

/// Decodes one CDR message of type T from `data` into *out. On failure returns
/// false and, if `error` is non-null, stores a description naming the message
/// type, field path and byte offset. Trailing bytes after the message are
/// ignored, as DDS may pad the payload.
template <RosMessage T>
bool DeserializeMessage(std::span<const std::byte> data, T* out, std::string* error = nullptr) {
  CdrReader reader(data, MessageTraits<T>::kName);
  if (reader.ok()) Deserialize(reader, out);
  if (!reader.ok() && error != nullptr) *error = reader.error();
  return reader.ok();
}

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_MSGS_MESSAGE_TRAITS_H_
