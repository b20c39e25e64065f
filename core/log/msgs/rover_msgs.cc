#include "core/log/msgs/rover_msgs.h"

#include "core/log/msgs/definitions.h"

namespace rover::log {
namespace rover_msgs {
namespace {

// Fewest bytes a LogChannelHealth can occupy (empty topic's length prefix and
// the counters), used to reject impossible element counts before allocating.
constexpr size_t kMinLogChannelHealthSize = 24;
// int32 robot, int64 submap, Pose (7 float64), float64[36] (padding may add 4).
constexpr size_t kMinSubmapOriginSize = 4 + 8 + 7 * 8 + 36 * 8;

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

void Serialize(const GraphFactor& msg, CdrWriter& writer) {
  Serialize(msg.header, writer);
  writer.WriteU64(msg.id);
  writer.WriteU8(msg.kind);
  writer.WriteString(msg.key_a);
  writer.WriteString(msg.key_b);
  writer.WriteF64Array(msg.p_a_b_m);
  writer.WriteF64Array(msg.q_a_b_wxyz);
  writer.WriteF64Array(msg.covariance);
  writer.WriteBool(msg.robust);
}

void Serialize(const SubmapOrigin& msg, CdrWriter& writer) {
  writer.WriteI32(msg.robot);
  writer.WriteI64(msg.submap);
  Serialize(msg.pose, writer);
  writer.WriteF64Array(msg.covariance);
}

void Serialize(const SubmapOrigins& msg, CdrWriter& writer) {
  Serialize(msg.header, writer);
  writer.WriteU64(msg.update);
  writer.WriteSequenceSize(msg.origins.size());
  for (const SubmapOrigin& origin : msg.origins) Serialize(origin, writer);
}

bool Deserialize(CdrReader& reader, GraphFactor* msg) {
  return reader.ReadNested("header", &msg->header) && reader.ReadU64("id", &msg->id) &&
         reader.ReadU8("kind", &msg->kind) && reader.ReadString("key_a", &msg->key_a) &&
         reader.ReadString("key_b", &msg->key_b) && reader.ReadF64Array("p_a_b_m", msg->p_a_b_m) &&
         reader.ReadF64Array("q_a_b_wxyz", msg->q_a_b_wxyz) &&
         reader.ReadF64Array("covariance", msg->covariance) &&
         reader.ReadBool("robust", &msg->robust);
}

bool Deserialize(CdrReader& reader, SubmapOrigin* msg) {
  return reader.ReadI32("robot", &msg->robot) && reader.ReadI64("submap", &msg->submap) &&
         reader.ReadNested("pose", &msg->pose) &&
         reader.ReadF64Array("covariance", msg->covariance);
}

bool Deserialize(CdrReader& reader, SubmapOrigins* msg) {
  return reader.ReadNested("header", &msg->header) && reader.ReadU64("update", &msg->update) &&
         reader.ReadSequence("origins", &msg->origins, kMinSubmapOriginSize);
}

void Serialize(const TagDetection& msg, CdrWriter& writer) {
  Serialize(msg.header, writer);
  writer.WriteString(msg.family);
  writer.WriteI32(msg.id);
  writer.WriteBool(msg.accepted);
  writer.WriteString(msg.refusal);
  writer.WriteF64Array(msg.corners_px);
  writer.WriteF64(msg.decision_margin);
  writer.WriteI32(msg.hamming);
  Serialize(msg.pose, writer);
  Serialize(msg.alternative_pose, writer);
  writer.WriteF64(msg.reprojection_rmse_px);
  writer.WriteF64(msg.ambiguity_ratio);
  writer.WriteF64(msg.distance_m);
  writer.WriteF64(msg.tilt_rad);
  writer.WriteF64Array(msg.covariance);
  writer.WriteU32(msg.flipped);
}

bool Deserialize(CdrReader& reader, TagDetection* msg) {
  return reader.ReadNested("header", &msg->header) && reader.ReadString("family", &msg->family) &&
         reader.ReadI32("id", &msg->id) && reader.ReadBool("accepted", &msg->accepted) &&
         reader.ReadString("refusal", &msg->refusal) &&
         reader.ReadF64Array("corners_px", msg->corners_px) &&
         reader.ReadF64("decision_margin", &msg->decision_margin) &&
         reader.ReadI32("hamming", &msg->hamming) && reader.ReadNested("pose", &msg->pose) &&
         reader.ReadNested("alternative_pose", &msg->alternative_pose) &&
         reader.ReadF64("reprojection_rmse_px", &msg->reprojection_rmse_px) &&
         reader.ReadF64("ambiguity_ratio", &msg->ambiguity_ratio) &&
         reader.ReadF64("distance_m", &msg->distance_m) &&
         reader.ReadF64("tilt_rad", &msg->tilt_rad) &&
         reader.ReadF64Array("covariance", msg->covariance) &&
         reader.ReadU32("flipped", &msg->flipped);
}

void Serialize(const TeamMessage& msg, CdrWriter& writer) {
  Serialize(msg.header, writer);
  writer.WriteI32(msg.origin);
  writer.WriteU8(msg.stream);
  writer.WriteU64(msg.seq);
  writer.WriteSequenceSize(msg.data.size());
  writer.WriteU8Array(msg.data);
}

bool Deserialize(CdrReader& reader, TeamMessage* msg) {
  return reader.ReadNested("header", &msg->header) && reader.ReadI32("origin", &msg->origin) &&
         reader.ReadU8("stream", &msg->stream) && reader.ReadU64("seq", &msg->seq) &&
         reader.ReadU8Sequence("data", &msg->data);
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

std::string_view MessageTraits<rover_msgs::GraphFactor>::Definition() {
  return internal::CachedDefinition<rover_msgs::GraphFactor>();
}

std::string_view MessageTraits<rover_msgs::SubmapOrigin>::Definition() {
  return internal::CachedDefinition<rover_msgs::SubmapOrigin>();
}

std::string_view MessageTraits<rover_msgs::SubmapOrigins>::Definition() {
  return internal::CachedDefinition<rover_msgs::SubmapOrigins>();
}

std::string_view MessageTraits<rover_msgs::TagDetection>::Definition() {
  return internal::CachedDefinition<rover_msgs::TagDetection>();
}

std::string_view MessageTraits<rover_msgs::TeamMessage>::Definition() {
  return internal::CachedDefinition<rover_msgs::TeamMessage>();
}

}  // namespace rover::log
