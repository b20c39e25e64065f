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

}  // namespace sensor_msgs

std::string_view MessageTraits<sensor_msgs::Imu>::Definition() {
  return internal::CachedDefinition<sensor_msgs::Imu>();
}

std::string_view MessageTraits<sensor_msgs::Image>::Definition() {
  return internal::CachedDefinition<sensor_msgs::Image>();
}

}  // namespace rover::log
