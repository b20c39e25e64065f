#ifndef ROVER_CORE_LOG_MSGS_SENSOR_MSGS_H_
#define ROVER_CORE_LOG_MSGS_SENSOR_MSGS_H_

// sensor_msgs: Imu (real-time, allocation-free) and Image (host side).

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/log/cdr/cdr_reader.h"
#include "core/log/cdr/cdr_writer.h"
#include "core/log/msgs/geometry_msgs.h"
#include "core/log/msgs/message_traits.h"
#include "core/log/msgs/std_msgs.h"

namespace rover::log {
namespace sensor_msgs {

/// sensor_msgs/msg/Imu. Covariances are row-major 3x3 about the x, y, z axes;
/// by ROS convention element 0 set to -1 means "this quantity is not provided".
/// Trivially copyable; serialises without allocation.
struct Imu {
  std_msgs::Header header;
  geometry_msgs::Quaternion orientation;
  std::array<double, 9> orientation_covariance{};
  geometry_msgs::Vector3 angular_velocity;
  std::array<double, 9> angular_velocity_covariance{};
  geometry_msgs::Vector3 linear_acceleration;
  std::array<double, 9> linear_acceleration_covariance{};

  friend bool operator==(const Imu&, const Imu&) = default;
};

/// sensor_msgs/msg/Image: `height` rows of `step` bytes each in `data`.
/// Host-side only (the pixel buffer is a std::vector).
struct Image {
  std_msgs::Header header;
  uint32_t height = 0;
  uint32_t width = 0;
  std::string encoding;  // e.g. "mono8", "rgb8", "16UC1" (sensor_msgs image_encodings).
  uint8_t is_bigendian = 0;
  uint32_t step = 0;  // Row length in bytes.
  std::vector<uint8_t> data;

  friend bool operator==(const Image&, const Image&) = default;
};

/// sensor_msgs/msg/PointField: one field of a PointCloud2 point.
struct PointField {
  static constexpr uint8_t kInt8 = 1;
  static constexpr uint8_t kUint8 = 2;
  static constexpr uint8_t kInt16 = 3;
  static constexpr uint8_t kUint16 = 4;
  static constexpr uint8_t kInt32 = 5;
  static constexpr uint8_t kUint32 = 6;
  static constexpr uint8_t kFloat32 = 7;
  static constexpr uint8_t kFloat64 = 8;

  std::string name;
  uint32_t offset = 0;  // Bytes from the start of the point.
  uint8_t datatype = 0;
  uint32_t count = 1;  // Elements in the field.

  friend bool operator==(const PointField&, const PointField&) = default;
};

/// sensor_msgs/msg/PointCloud2: `height` rows of `width` points, each
/// `point_step` bytes laid out by `fields`. Host-side (vectors).
struct PointCloud2 {
  std_msgs::Header header;
  uint32_t height = 1;
  uint32_t width = 0;
  std::vector<PointField> fields;
  bool is_bigendian = false;
  uint32_t point_step = 0;
  uint32_t row_step = 0;
  std::vector<uint8_t> data;
  bool is_dense = true;

  friend bool operator==(const PointCloud2&, const PointCloud2&) = default;
};

void Serialize(const Imu& msg, CdrWriter& writer);
void Serialize(const Image& msg, CdrWriter& writer);
void Serialize(const PointField& msg, CdrWriter& writer);
void Serialize(const PointCloud2& msg, CdrWriter& writer);
bool Deserialize(CdrReader& reader, Imu* msg);
bool Deserialize(CdrReader& reader, Image* msg);
bool Deserialize(CdrReader& reader, PointField* msg);
bool Deserialize(CdrReader& reader, PointCloud2* msg);

}  // namespace sensor_msgs

template <>
struct MessageTraits<sensor_msgs::Imu> {
  static constexpr std::string_view kName = "sensor_msgs/msg/Imu";
  static std::string_view Definition();
};

template <>
struct MessageTraits<sensor_msgs::Image> {
  static constexpr std::string_view kName = "sensor_msgs/msg/Image";
  static std::string_view Definition();
};

template <>
struct MessageTraits<sensor_msgs::PointField> {
  static constexpr std::string_view kName = "sensor_msgs/msg/PointField";
  static std::string_view Definition();
};

template <>
struct MessageTraits<sensor_msgs::PointCloud2> {
  static constexpr std::string_view kName = "sensor_msgs/msg/PointCloud2";
  static std::string_view Definition();
};

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_MSGS_SENSOR_MSGS_H_
