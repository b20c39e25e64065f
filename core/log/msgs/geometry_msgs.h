#ifndef ROVER_CORE_LOG_MSGS_GEOMETRY_MSGS_H_
#define ROVER_CORE_LOG_MSGS_GEOMETRY_MSGS_H_

// geometry_msgs: vectors, poses, twists and transforms. All types here are
// trivially copyable and serialise without allocation.

#include <array>
#include <string_view>

#include "core/log/cdr/cdr_reader.h"
#include "core/log/cdr/cdr_writer.h"
#include "core/log/msgs/inline_string.h"
#include "core/log/msgs/message_traits.h"
#include "core/log/msgs/std_msgs.h"

namespace rover::log {
namespace geometry_msgs {

/// geometry_msgs/msg/Vector3.
struct Vector3 {
  double x = 0.0;
  double y = 0.0;
  double z = 0.0;

  friend bool operator==(const Vector3&, const Vector3&) = default;
};

/// geometry_msgs/msg/Point.
struct Point {
  double x = 0.0;
  double y = 0.0;
  double z = 0.0;

  friend bool operator==(const Point&, const Point&) = default;
};

/// geometry_msgs/msg/Quaternion. Defaults to identity, as in ROS 2.
struct Quaternion {
  double x = 0.0;
  double y = 0.0;
  double z = 0.0;
  double w = 1.0;

  friend bool operator==(const Quaternion&, const Quaternion&) = default;
};

/// geometry_msgs/msg/Pose.
struct Pose {
  Point position;
  Quaternion orientation;

  friend bool operator==(const Pose&, const Pose&) = default;
};

/// geometry_msgs/msg/PoseWithCovariance. Row-major 6x6 covariance over
/// (x, y, z, rotation about X, rotation about Y, rotation about Z).
struct PoseWithCovariance {
  Pose pose;
  std::array<double, 36> covariance{};

  friend bool operator==(const PoseWithCovariance&, const PoseWithCovariance&) = default;
};

/// geometry_msgs/msg/PoseWithCovarianceStamped.
struct PoseWithCovarianceStamped {
  std_msgs::Header header;
  PoseWithCovariance pose;

  friend bool operator==(const PoseWithCovarianceStamped&,
                         const PoseWithCovarianceStamped&) = default;
};

/// geometry_msgs/msg/Twist.
struct Twist {
  Vector3 linear;
  Vector3 angular;

  friend bool operator==(const Twist&, const Twist&) = default;
};

/// geometry_msgs/msg/TwistWithCovariance (row-major 6x6, as for the pose).
struct TwistWithCovariance {
  Twist twist;
  std::array<double, 36> covariance{};

  friend bool operator==(const TwistWithCovariance&, const TwistWithCovariance&) = default;
};

/// geometry_msgs/msg/Transform.
struct Transform {
  Vector3 translation;
  Quaternion rotation;

  friend bool operator==(const Transform&, const Transform&) = default;
};

/// geometry_msgs/msg/TransformStamped: the pose of child_frame_id in
/// header.frame_id.
struct TransformStamped {
  std_msgs::Header header;
  FrameId child_frame_id;
  Transform transform;

  friend bool operator==(const TransformStamped&, const TransformStamped&) = default;
};

void Serialize(const Vector3& msg, CdrWriter& writer);
void Serialize(const Point& msg, CdrWriter& writer);
void Serialize(const Quaternion& msg, CdrWriter& writer);
void Serialize(const Pose& msg, CdrWriter& writer);
void Serialize(const PoseWithCovariance& msg, CdrWriter& writer);
void Serialize(const PoseWithCovarianceStamped& msg, CdrWriter& writer);
void Serialize(const Twist& msg, CdrWriter& writer);
void Serialize(const TwistWithCovariance& msg, CdrWriter& writer);
void Serialize(const Transform& msg, CdrWriter& writer);
void Serialize(const TransformStamped& msg, CdrWriter& writer);

bool Deserialize(CdrReader& reader, Vector3* msg);
bool Deserialize(CdrReader& reader, Point* msg);
bool Deserialize(CdrReader& reader, Quaternion* msg);
bool Deserialize(CdrReader& reader, Pose* msg);
bool Deserialize(CdrReader& reader, PoseWithCovariance* msg);
bool Deserialize(CdrReader& reader, PoseWithCovarianceStamped* msg);
bool Deserialize(CdrReader& reader, Twist* msg);
bool Deserialize(CdrReader& reader, TwistWithCovariance* msg);
bool Deserialize(CdrReader& reader, Transform* msg);
/// Fails if a frame id exceeds FrameId::kCapacity.
bool Deserialize(CdrReader& reader, TransformStamped* msg);

}  // namespace geometry_msgs

template <>
struct MessageTraits<geometry_msgs::Vector3> {
  static constexpr std::string_view kName = "geometry_msgs/msg/Vector3";
  static std::string_view Definition();
};

template <>
struct MessageTraits<geometry_msgs::Point> {
  static constexpr std::string_view kName = "geometry_msgs/msg/Point";
  static std::string_view Definition();
};

template <>
struct MessageTraits<geometry_msgs::Quaternion> {
  static constexpr std::string_view kName = "geometry_msgs/msg/Quaternion";
  static std::string_view Definition();
};

template <>
struct MessageTraits<geometry_msgs::Pose> {
  static constexpr std::string_view kName = "geometry_msgs/msg/Pose";
  static std::string_view Definition();
};

template <>
struct MessageTraits<geometry_msgs::PoseWithCovariance> {
  static constexpr std::string_view kName = "geometry_msgs/msg/PoseWithCovariance";
  static std::string_view Definition();
};

template <>
struct MessageTraits<geometry_msgs::PoseWithCovarianceStamped> {
  static constexpr std::string_view kName = "geometry_msgs/msg/PoseWithCovarianceStamped";
  static std::string_view Definition();
};

template <>
struct MessageTraits<geometry_msgs::Twist> {
  static constexpr std::string_view kName = "geometry_msgs/msg/Twist";
  static std::string_view Definition();
};

template <>
struct MessageTraits<geometry_msgs::TwistWithCovariance> {
  static constexpr std::string_view kName = "geometry_msgs/msg/TwistWithCovariance";
  static std::string_view Definition();
};

template <>
struct MessageTraits<geometry_msgs::Transform> {
  static constexpr std::string_view kName = "geometry_msgs/msg/Transform";
  static std::string_view Definition();
};

template <>
struct MessageTraits<geometry_msgs::TransformStamped> {
  static constexpr std::string_view kName = "geometry_msgs/msg/TransformStamped";
  static std::string_view Definition();
};

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_MSGS_GEOMETRY_MSGS_H_
