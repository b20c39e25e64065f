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

void Serialize(const SubmapInfo& msg, CdrWriter& writer) {
  Serialize(msg.header, writer);
  writer.WriteU32(msg.index);
  writer.WriteU32(msg.frame_id);
  writer.WriteBool(msg.has_origin);
  writer.WriteU32(msg.previous_frame_id);
  writer.WriteI64(msg.origin_stamp_ns);
  writer.WriteF64Array(msg.p_previous_origin_m);
  writer.WriteF64(msg.yaw_previous_origin_rad);
  writer.WriteF64Array(msg.origin_covariance);
  writer.WriteI64(msg.first_stamp_ns);
  writer.WriteI64(msg.last_stamp_ns);
  writer.WriteU32(msg.images);
  writer.WriteF64(msg.distance_m);
  writer.WriteU64(msg.octree_bytes);
  writer.WriteU64(msg.cloud_bytes);
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

bool Deserialize(CdrReader& reader, SubmapInfo* msg) {
  return reader.ReadNested("header", &msg->header) && reader.ReadU32("index", &msg->index) &&
         reader.ReadU32("frame_id", &msg->frame_id) &&
         reader.ReadBool("has_origin", &msg->has_origin) &&
         reader.ReadU32("previous_frame_id", &msg->previous_frame_id) &&
         reader.ReadI64("origin_stamp_ns", &msg->origin_stamp_ns) &&
         reader.ReadF64Array("p_previous_origin_m", msg->p_previous_origin_m) &&
         reader.ReadF64("yaw_previous_origin_rad", &msg->yaw_previous_origin_rad) &&
         reader.ReadF64Array("origin_covariance", msg->origin_covariance) &&
         reader.ReadI64("first_stamp_ns", &msg->first_stamp_ns) &&
         reader.ReadI64("last_stamp_ns", &msg->last_stamp_ns) &&
         reader.ReadU32("images", &msg->images) && reader.ReadF64("distance_m", &msg->distance_m) &&
         reader.ReadU64("octree_bytes", &msg->octree_bytes) &&
         reader.ReadU64("cloud_bytes", &msg->cloud_bytes);
}

}  // namespace rover_msgs

std::string_view MessageTraits<rover_msgs::LogChannelHealth>::Definition() {
  return internal::CachedDefinition<rover_msgs::LogChannelHealth>();
}

std::string_view MessageTraits<rover_msgs::LogHealth>::Definition() {
  return internal::CachedDefinition<rover_msgs::LogHealth>();
}

std::string_view MessageTraits<rover_msgs::SubmapInfo>::Definition() {
  return internal::CachedDefinition<rover_msgs::SubmapInfo>();
}

}  // namespace rover::log
