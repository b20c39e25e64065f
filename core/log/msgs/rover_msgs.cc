#include "core/log/msgs/rover_msgs.h"

#include "core/log/msgs/definitions.h"

namespace rover::log {
namespace rover_msgs {
namespace {

// Fewest bytes a LogChannelHealth can occupy (empty topic's length prefix and
// the counters), used to reject impossible element counts before allocating.
constexpr size_t kMinLogChannelHealthSize = 24;

}  // namespace

void Serialize(const LogChannelHealth& msg, CdrWriter& writer) {
  writer.WriteString(msg.topic);
  writer.WriteU64(msg.records_written);
  writer.WriteU64(msg.records_dropped);
  writer.WriteU32(msg.ring_high_water);
}

void Serialize(const LogHealth& msg, CdrWriter& writer) {
  Serialize(msg.header, writer);
  writer.WriteU64(msg.records_written);
  writer.WriteU64(msg.bytes_written);
  writer.WriteSequenceSize(msg.channels.size());
  for (const LogChannelHealth& channel : msg.channels) Serialize(channel, writer);
}

bool Deserialize(CdrReader& reader, LogChannelHealth* msg) {
  return reader.ReadString("topic", &msg->topic) &&
         reader.ReadU64("records_written", &msg->records_written) &&
         reader.ReadU64("records_dropped", &msg->records_dropped) &&
         reader.ReadU32("ring_high_water", &msg->ring_high_water);
}

bool Deserialize(CdrReader& reader, LogHealth* msg) {
  return reader.ReadNested("header", &msg->header) &&
         reader.ReadU64("records_written", &msg->records_written) &&
         reader.ReadU64("bytes_written", &msg->bytes_written) &&
         reader.ReadSequence("channels", &msg->channels, kMinLogChannelHealthSize);
}

}  // namespace rover_msgs

std::string_view MessageTraits<rover_msgs::LogChannelHealth>::Definition() {
  return internal::CachedDefinition<rover_msgs::LogChannelHealth>();
}

std::string_view MessageTraits<rover_msgs::LogHealth>::Definition() {
  return internal::CachedDefinition<rover_msgs::LogHealth>();
}

}  // namespace rover::log
