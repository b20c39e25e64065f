#ifndef ROVER_CORE_LOG_MSGS_DIAGNOSTIC_MSGS_H_
#define ROVER_CORE_LOG_MSGS_DIAGNOSTIC_MSGS_H_

// diagnostic_msgs: KeyValue, DiagnosticStatus, DiagnosticArray (host side).

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/log/cdr/cdr_reader.h"
#include "core/log/cdr/cdr_writer.h"
#include "core/log/msgs/message_traits.h"
#include "core/log/msgs/std_msgs.h"

namespace rover::log {
namespace diagnostic_msgs {

/// diagnostic_msgs/msg/KeyValue.
struct KeyValue {
  std::string key;
  std::string value;

  friend bool operator==(const KeyValue&, const KeyValue&) = default;
};

/// diagnostic_msgs/msg/DiagnosticStatus.
struct DiagnosticStatus {
  // Values of `level` (the message's OK/WARN/ERROR/STALE byte constants).
  static constexpr uint8_t kOk = 0;
  static constexpr uint8_t kWarn = 1;
  static constexpr uint8_t kError = 2;
  static constexpr uint8_t kStale = 3;

  uint8_t level = kOk;
  std::string name;         // Component reporting, e.g. "imu: driver".
  std::string message;      // Human-readable status.
  std::string hardware_id;  // Unique id of the hardware, if any.
  std::vector<KeyValue> values;

  friend bool operator==(const DiagnosticStatus&, const DiagnosticStatus&) = default;
};

/// diagnostic_msgs/msg/DiagnosticArray.
struct DiagnosticArray {
  std_msgs::Header header;
  std::vector<DiagnosticStatus> status;

  friend bool operator==(const DiagnosticArray&, const DiagnosticArray&) = default;
};

void Serialize(const KeyValue& msg, CdrWriter& writer);
void Serialize(const DiagnosticStatus& msg, CdrWriter& writer);
void Serialize(const DiagnosticArray& msg, CdrWriter& writer);
bool Deserialize(CdrReader& reader, KeyValue* msg);
bool Deserialize(CdrReader& reader, DiagnosticStatus* msg);
bool Deserialize(CdrReader& reader, DiagnosticArray* msg);

}  // namespace diagnostic_msgs

template <>
struct MessageTraits<diagnostic_msgs::KeyValue> {
  static constexpr std::string_view kName = "diagnostic_msgs/msg/KeyValue";
  static std::string_view Definition();
};

template <>
struct MessageTraits<diagnostic_msgs::DiagnosticStatus> {
  static constexpr std::string_view kName = "diagnostic_msgs/msg/DiagnosticStatus";
  static std::string_view Definition();
};

template <>
struct MessageTraits<diagnostic_msgs::DiagnosticArray> {
  static constexpr std::string_view kName = "diagnostic_msgs/msg/DiagnosticArray";
  static std::string_view Definition();
};

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_MSGS_DIAGNOSTIC_MSGS_H_
