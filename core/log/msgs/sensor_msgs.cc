#include "core/log/msgs/sensor_msgs.h"

#include "core/log/msgs/definitions.h"

namespace rover::log {
namespace sensor_msgs {

void Serialize(const Imu& msg, CdrWriter& writer) {
  Serialize(msg.header, writer);
  Serialize(msg.orientation, writer);
  writer.WriteF64Array(msg.orientation_covariance);
  Serialize(msg.angular_velocity, writer);
  writer.WriteF64Array(msg.angular_velocity_covariance);
  Serialize(msg.linear_acceleration, writer);
  writer.WriteF64Array(msg.linear_acceleration_covariance);
}

void Serialize(const Image& msg, CdrWriter& writer) {
  Serialize(msg.header, writer);
  writer.WriteU32(msg.height);
  writer.WriteU32(msg.width);
  writer.WriteString(msg.encoding);
  writer.WriteU8(msg.is_bigendian);
  writer.WriteU32(msg.step);
  writer.WriteSequenceSize(msg.data.size());
  writer.WriteU8Array(msg.data);
}

void Serialize(const PointField& msg, CdrWriter& writer) {
  writer.WriteString(msg.name);
  writer.WriteU32(msg.offset);
  writer.WriteU8(msg.datatype);
  writer.WriteU32(msg.count);
}

void Serialize(const PointCloud2& msg, CdrWriter& writer) {
  Serialize(msg.header, writer);
  writer.WriteU32(msg.height);
  writer.WriteU32(msg.width);
  writer.WriteSequenceSize(msg.fields.size());
  for (const PointField& field : msg.fields) Serialize(field, writer);
  writer.WriteBool(msg.is_bigendian);
  writer.WriteU32(msg.point_step);
  writer.WriteU32(msg.row_step);
  writer.WriteSequenceSize(msg.data.size());
  writer.WriteU8Array(msg.data);
  writer.WriteBool(msg.is_dense);
}

bool Deserialize(CdrReader& reader, Imu* msg) {
  return reader.ReadNested("header", &msg->header) &&
         reader.ReadNested("orientation", &msg->orientation) &&
         reader.ReadF64Array("orientation_covariance", msg->orientation_covariance) &&
         reader.ReadNested("angular_velocity", &msg->angular_velocity) &&
         reader.ReadF64Array("angular_velocity_covariance", msg->angular_velocity_covariance) &&
         reader.ReadNested("linear_acceleration", &msg->linear_acceleration) &&
         reader.ReadF64Array("linear_acceleration_covariance", msg->linear_acceleration_covariance);
}

bool Deserialize(CdrReader& reader, Image* msg) {
  return reader.ReadNested("header", &msg->header) && reader.ReadU32("height", &msg->height) &&
         reader.ReadU32("width", &msg->width) && reader.ReadString("encoding", &msg->encoding) &&
         reader.ReadU8("is_bigendian", &msg->is_bigendian) && reader.ReadU32("step", &msg->step) &&
         reader.ReadU8Sequence("data", &msg->data);
}

bool Deserialize(CdrReader& reader, PointField* msg) {
  return reader.ReadString("name", &msg->name) && reader.ReadU32("offset", &msg->offset) &&
         reader.ReadU8("datatype", &msg->datatype) && reader.ReadU32("count", &msg->count);
}

bool Deserialize(CdrReader& reader, PointCloud2* msg) {
  // A PointField takes at least its name's length prefix, offset, datatype
  // (padded) and count: 13 bytes.
  constexpr size_t kMinPointFieldSize = 13;
  return reader.ReadNested("header", &msg->header) && reader.ReadU32("height", &msg->height) &&
         reader.ReadU32("width", &msg->width) &&
         reader.ReadSequence("fields", &msg->fields, kMinPointFieldSize) &&
         reader.ReadBool("is_bigendian", &msg->is_bigendian) &&
         reader.ReadU32("point_step", &msg->point_step) &&
         reader.ReadU32("row_step", &msg->row_step) && reader.ReadU8Sequence("data", &msg->data) &&
         reader.ReadBool("is_dense", &msg->is_dense);
}

}  // namespace sensor_msgs

std::string_view MessageTraits<sensor_msgs::Imu>::Definition() {
  return internal::CachedDefinition<sensor_msgs::Imu>();
}

std::string_view MessageTraits<sensor_msgs::Image>::Definition() {
  return internal::CachedDefinition<sensor_msgs::Image>();
}

std::string_view MessageTraits<sensor_msgs::PointField>::Definition() {
  return internal::CachedDefinition<sensor_msgs::PointField>();
}

std::string_view MessageTraits<sensor_msgs::PointCloud2>::Definition() {
  return internal::CachedDefinition<sensor_msgs::PointCloud2>();
}

}  // namespace rover::log
