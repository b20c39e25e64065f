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

void Serialize(const Imu& msg, CdrWriter& writer);
void Serialize(const Image& msg, CdrWriter& writer);
bool Deserialize(CdrReader& reader, Imu* msg);
bool Deserialize(CdrReader& reader, Image* msg);

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

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_MSGS_SENSOR_MSGS_H_
