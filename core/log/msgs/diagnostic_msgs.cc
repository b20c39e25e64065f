#include "core/log/msgs/diagnostic_msgs.h"

#include "core/log/msgs/definitions.h"

namespace rover::log {
namespace diagnostic_msgs {
namespace {

// Fewest bytes an element can occupy (length prefixes of empty strings and
// sequences, the level byte), used to reject impossible element counts before
// allocating.
constexpr size_t kMinKeyValueSize = 8;
constexpr size_t kMinDiagnosticStatusSize = 17;

}  // namespace

void Serialize(const KeyValue& msg, CdrWriter& writer) {
  writer.WriteString(msg.key);
  writer.WriteString(msg.value);
}

void Serialize(const DiagnosticStatus& msg, CdrWriter& writer) {
  writer.WriteU8(msg.level);
  writer.WriteString(msg.name);
  writer.WriteString(msg.message);
  writer.WriteString(msg.hardware_id);
  writer.WriteSequenceSize(msg.values.size());
  for (const KeyValue& value : msg.values) Serialize(value, writer);
}

void Serialize(const DiagnosticArray& msg, CdrWriter& writer) {
  Serialize(msg.header, writer);
  writer.WriteSequenceSize(msg.status.size());
  for (const DiagnosticStatus& status : msg.status) Serialize(status, writer);
}

bool Deserialize(CdrReader& reader, KeyValue* msg) {
  return reader.ReadString("key", &msg->key) && reader.ReadString("value", &msg->value);
}

bool Deserialize(CdrReader& reader, DiagnosticStatus* msg) {
  return reader.ReadU8("level", &msg->level) && reader.ReadString("name", &msg->name) &&
         reader.ReadString("message", &msg->message) &&
         reader.ReadString("hardware_id", &msg->hardware_id) &&
         reader.ReadSequence("values", &msg->values, kMinKeyValueSize);
}

bool Deserialize(CdrReader& reader, DiagnosticArray* msg) {
  return reader.ReadNested("header", &msg->header) &&
         reader.ReadSequence("status", &msg->status, kMinDiagnosticStatusSize);
}

}  // namespace diagnostic_msgs

std::string_view MessageTraits<diagnostic_msgs::KeyValue>::Definition() {
  return internal::CachedDefinition<diagnostic_msgs::KeyValue>();
}

std::string_view MessageTraits<diagnostic_msgs::DiagnosticStatus>::Definition() {
  return internal::CachedDefinition<diagnostic_msgs::DiagnosticStatus>();
}

std::string_view MessageTraits<diagnostic_msgs::DiagnosticArray>::Definition() {
  return internal::CachedDefinition<diagnostic_msgs::DiagnosticArray>();
}

}  // namespace rover::log
