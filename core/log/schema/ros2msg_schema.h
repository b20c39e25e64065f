#ifndef ROVER_CORE_LOG_SCHEMA_ROS2MSG_SCHEMA_H_
#define ROVER_CORE_LOG_SCHEMA_ROS2MSG_SCHEMA_H_

// Parser for the `ros2msg` schema encoding that MCAP's ros2 profile uses:
// a message definition in ROS 2 .msg syntax, followed by each dependency,
// separated by a line of '=' and a line "MSG: pkg/Type". Host tools use the
// parsed form to decode messages whose type they were not compiled against.

#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace rover::log {

/// Error in a schema text; the message names the type and the 1-based line.
class SchemaError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The primitive kinds of ROS 2 IDL, plus kMessage for nested types.
enum class FieldKind {
  kBool,
  kByte,
  kChar,
  kInt8,
  kUint8,
  kInt16,
  kUint16,
  kInt32,
  kUint32,
  kInt64,
  kUint64,
  kFloat32,
  kFloat64,
  kString,
  kWString,
  kMessage,
};

/// How many values a field holds.
enum class ArrayKind {
  kScalar,     ///< one value
  kFixed,      ///< T[N]: exactly N values, no length prefix on the wire
  kUnbounded,  ///< T[]: u32 count, then the values
  kBounded,    ///< T[<=N]: like kUnbounded, at most N values
};

/// One field of a message definition.
struct FieldDefinition {
  std::string name;
  FieldKind kind = FieldKind::kInt32;
  std::string type_name;  ///< fully qualified "pkg/msg/Type" when kind == kMessage
  ArrayKind array = ArrayKind::kScalar;
  uint32_t array_size = 0;  ///< N for kFixed and kBounded
};

/// One message type: its fields in wire order (constants are not fields).
struct MessageDefinition {
  std::string name;  ///< "pkg/msg/Type"
  std::vector<FieldDefinition> fields;
};

/// A parsed schema: the root type and every type it depends on.
class Ros2MsgSchema {
 public:
  /// Parses `text` whose root type is `root_name` (e.g. "sensor_msgs/msg/Imu").
  /// Throws SchemaError naming the type and line on malformed input, on a
  /// field of a type that is defined nowhere in the text, and on recursion.
  static Ros2MsgSchema Parse(std::string_view root_name, std::string_view text);

  const MessageDefinition& root() const { return types_.at(root_name_); }
  /// The definition of `name` ("pkg/msg/Type"); throws SchemaError if absent.
  const MessageDefinition& Type(const std::string& name) const;
  const std::map<std::string, MessageDefinition>& types() const { return types_; }

 private:
  std::string root_name_;
  std::map<std::string, MessageDefinition> types_;
};

/// Normalises "pkg/Type" and "pkg/msg/Type" to "pkg/msg/Type".
std::string NormalizeTypeName(std::string_view name);

/// Size in bytes of a primitive on the wire; 0 for strings and messages.
std::size_t PrimitiveSize(FieldKind kind);

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_SCHEMA_ROS2MSG_SCHEMA_H_
