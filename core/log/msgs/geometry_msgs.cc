#include "core/log/msgs/geometry_msgs.h"

#include "core/log/msgs/definitions.h"
#include "core/log/msgs/field_io.h"

namespace rover::log {
namespace geometry_msgs {

void Serialize(const Vector3& msg, CdrWriter& writer) {
  writer.WriteF64(msg.x);
  writer.WriteF64(msg.y);
  writer.WriteF64(msg.z);
}

void Serialize(const Point& msg, CdrWriter& writer) {
  writer.WriteF64(msg.x);
  writer.WriteF64(msg.y);
  writer.WriteF64(msg.z);
}

void Serialize(const Quaternion& msg, CdrWriter& writer) {
  writer.WriteF64(msg.x);
  writer.WriteF64(msg.y);
  writer.WriteF64(msg.z);
  writer.WriteF64(msg.w);
}

void Serialize(const Pose& msg, CdrWriter& writer) {
  Serialize(msg.position, writer);
  Serialize(msg.orientation, writer);
}

void Serialize(const PoseWithCovariance& msg, CdrWriter& writer) {
  Serialize(msg.pose, writer);
  writer.WriteF64Array(msg.covariance);
}

void Serialize(const PoseWithCovarianceStamped& msg, CdrWriter& writer) {
  Serialize(msg.header, writer);
  Serialize(msg.pose, writer);
}

void Serialize(const Twist& msg, CdrWriter& writer) {
  Serialize(msg.linear, writer);
  Serialize(msg.angular, writer);
}

void Serialize(const TwistWithCovariance& msg, CdrWriter& writer) {
  Serialize(msg.twist, writer);
  writer.WriteF64Array(msg.covariance);
}

void Serialize(const Transform& msg, CdrWriter& writer) {
  Serialize(msg.translation, writer);
  Serialize(msg.rotation, writer);
}

void Serialize(const TransformStamped& msg, CdrWriter& writer) {
  Serialize(msg.header, writer);
  writer.WriteString(msg.child_frame_id.view());
  Serialize(msg.transform, writer);
}

bool Deserialize(CdrReader& reader, Vector3* msg) {
  return reader.ReadF64("x", &msg->x) && reader.ReadF64("y", &msg->y) &&
         reader.ReadF64("z", &msg->z);
}

bool Deserialize(CdrReader& reader, Point* msg) {
  return reader.ReadF64("x", &msg->x) && reader.ReadF64("y", &msg->y) &&
         reader.ReadF64("z", &msg->z);
}

bool Deserialize(CdrReader& reader, Quaternion* msg) {
  return reader.ReadF64("x", &msg->x) && reader.ReadF64("y", &msg->y) &&
         reader.ReadF64("z", &msg->z) && reader.ReadF64("w", &msg->w);
}

bool Deserialize(CdrReader& reader, Pose* msg) {
  return reader.ReadNested("position", &msg->position) &&
         reader.ReadNested("orientation", &msg->orientation);
}

bool Deserialize(CdrReader& reader, PoseWithCovariance* msg) {
  return reader.ReadNested("pose", &msg->pose) &&
         reader.ReadF64Array("covariance", msg->covariance);
}

bool Deserialize(CdrReader& reader, PoseWithCovarianceStamped* msg) {
  return reader.ReadNested("header", &msg->header) && reader.ReadNested("pose", &msg->pose);
}

bool Deserialize(CdrReader& reader, Twist* msg) {
  return reader.ReadNested("linear", &msg->linear) && reader.ReadNested("angular", &msg->angular);
}

bool Deserialize(CdrReader& reader, TwistWithCovariance* msg) {
  return reader.ReadNested("twist", &msg->twist) &&
         reader.ReadF64Array("covariance", msg->covariance);
}

bool Deserialize(CdrReader& reader, Transform* msg) {
  return reader.ReadNested("translation", &msg->translation) &&
         reader.ReadNested("rotation", &msg->rotation);
}

bool Deserialize(CdrReader& reader, TransformStamped* msg) {
  return reader.ReadNested("header", &msg->header) &&
         internal::ReadInlineString(reader, "child_frame_id", &msg->child_frame_id) &&
         reader.ReadNested("transform", &msg->transform);
}

}  // namespace geometry_msgs

std::string_view MessageTraits<geometry_msgs::Vector3>::Definition() {
  return internal::CachedDefinition<geometry_msgs::Vector3>();
}

std::string_view MessageTraits<geometry_msgs::Point>::Definition() {
  return internal::CachedDefinition<geometry_msgs::Point>();
}

std::string_view MessageTraits<geometry_msgs::Quaternion>::Definition() {
  return internal::CachedDefinition<geometry_msgs::Quaternion>();
}

std::string_view MessageTraits<geometry_msgs::Pose>::Definition() {
  return internal::CachedDefinition<geometry_msgs::Pose>();
}

std::string_view MessageTraits<geometry_msgs::PoseWithCovariance>::Definition() {
  return internal::CachedDefinition<geometry_msgs::PoseWithCovariance>();
}

std::string_view MessageTraits<geometry_msgs::PoseWithCovarianceStamped>::Definition() {
  return internal::CachedDefinition<geometry_msgs::PoseWithCovarianceStamped>();
}

std::string_view MessageTraits<geometry_msgs::Twist>::Definition() {
  return internal::CachedDefinition<geometry_msgs::Twist>();
}

std::string_view MessageTraits<geometry_msgs::TwistWithCovariance>::Definition() {
  return internal::CachedDefinition<geometry_msgs::TwistWithCovariance>();
}

std::string_view MessageTraits<geometry_msgs::Transform>::Definition() {
  return internal::CachedDefinition<geometry_msgs::Transform>();
}

std::string_view MessageTraits<geometry_msgs::TransformStamped>::Definition() {
  return internal::CachedDefinition<geometry_msgs::TransformStamped>();
}

}  // namespace rover::log
