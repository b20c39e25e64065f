#ifndef ROVER_TESTS_CORE_LOG_CDR_RANDOM_MSGS_H_
#define ROVER_TESTS_CORE_LOG_CDR_RANDOM_MSGS_H_

// Seeded random contents for every logged message type, so round-trip tests
// cover odd string lengths (every alignment case), empty and non-empty
// sequences and special floating-point values.

#include <array>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/log/msgs/all_msgs.h"

namespace rover::log::cdr_test {

class RandomMessages {
 public:
  explicit RandomMessages(uint64_t seed) : rng_(seed) {}

  template <typename T>
  T Make() {
    T msg;
    Fill(&msg);
    return msg;
  }

  void Fill(builtin_interfaces::Time* m) {
    m->sec = static_cast<int32_t>(rng_());
    m->nanosec = static_cast<uint32_t>(Uniform(0, 999'999'999));
  }
  void Fill(std_msgs::Header* m) {
    Fill(&m->stamp);
    m->frame_id = FrameId::Truncated(Text(FrameId::kCapacity));
  }
  void Fill(geometry_msgs::Vector3* m) {
    m->x = Real();
    m->y = Real();
    m->z = Real();
  }
  void Fill(geometry_msgs::Point* m) {
    m->x = Real();
    m->y = Real();
    m->z = Real();
  }
  void Fill(geometry_msgs::Quaternion* m) {
    m->x = Real();
    m->y = Real();
    m->z = Real();
    m->w = Real();
  }
  void Fill(geometry_msgs::Pose* m) {
    Fill(&m->position);
    Fill(&m->orientation);
  }
  void Fill(geometry_msgs::PoseWithCovariance* m) {
    Fill(&m->pose);
    FillArray(&m->covariance);
  }
  void Fill(geometry_msgs::PoseWithCovarianceStamped* m) {
    Fill(&m->header);
    Fill(&m->pose);
  }
  void Fill(geometry_msgs::Twist* m) {
    Fill(&m->linear);
    Fill(&m->angular);
  }
  void Fill(geometry_msgs::TwistWithCovariance* m) {
    Fill(&m->twist);
    FillArray(&m->covariance);
  }
  void Fill(geometry_msgs::Transform* m) {
    Fill(&m->translation);
    Fill(&m->rotation);
  }
  void Fill(geometry_msgs::TransformStamped* m) {
    Fill(&m->header);
    m->child_frame_id = FrameId::Truncated(Text(FrameId::kCapacity));
    Fill(&m->transform);
  }
  void Fill(sensor_msgs::Imu* m) {
    Fill(&m->header);
    Fill(&m->orientation);
    FillArray(&m->orientation_covariance);
    Fill(&m->angular_velocity);
    FillArray(&m->angular_velocity_covariance);
    Fill(&m->linear_acceleration);
    FillArray(&m->linear_acceleration_covariance);
  }
  void Fill(sensor_msgs::Image* m) {
    Fill(&m->header);
    m->height = static_cast<uint32_t>(rng_());
    m->width = static_cast<uint32_t>(rng_());
    m->encoding = Text(12);
    m->is_bigendian = static_cast<uint8_t>(Uniform(0, 1));
    m->step = static_cast<uint32_t>(rng_());
    m->data.resize(static_cast<size_t>(Uniform(0, 67)));
    for (uint8_t& b : m->data) b = static_cast<uint8_t>(rng_());
  }
  void Fill(sensor_msgs::PointField* m) {
    m->name = Text(9);
    m->offset = static_cast<uint32_t>(rng_());
    m->datatype = static_cast<uint8_t>(Uniform(1, 8));
    m->count = static_cast<uint32_t>(rng_());
  }
  void Fill(sensor_msgs::PointCloud2* m) {
    Fill(&m->header);
    m->height = static_cast<uint32_t>(rng_());
    m->width = static_cast<uint32_t>(rng_());
    FillVector(&m->fields);
    m->is_bigendian = Uniform(0, 1) == 1;
    m->point_step = static_cast<uint32_t>(rng_());
    m->row_step = static_cast<uint32_t>(rng_());
    FillOctets(&m->data);
    m->is_dense = Uniform(0, 1) == 1;
  }
  void Fill(nav_msgs::MapMetaData* m) {
    Fill(&m->map_load_time);
    m->resolution = static_cast<float>(Real());
    m->width = static_cast<uint32_t>(rng_());
    m->height = static_cast<uint32_t>(rng_());
    Fill(&m->origin);
  }
  void Fill(nav_msgs::OccupancyGrid* m) {
    Fill(&m->header);
    Fill(&m->info);
    FillOctets(&m->data);
  }
  void Fill(octomap_msgs::Octomap* m) {
    Fill(&m->header);
    m->binary = Uniform(0, 1) == 1;
    m->id = Text(10);
    m->resolution = Real();
    FillOctets(&m->data);
  }
  void Fill(rover_msgs::SubmapInfo* m) {
    Fill(&m->header);
    m->index = static_cast<uint32_t>(rng_());
    m->frame_id = static_cast<uint32_t>(rng_());
    m->has_origin = Uniform(0, 1) == 1;
    m->previous_frame_id = static_cast<uint32_t>(rng_());
    m->origin_stamp_ns = static_cast<int64_t>(rng_());
    FillArray(&m->p_previous_origin_m);
    m->yaw_previous_origin_rad = Real();
    FillArray(&m->origin_covariance);
    m->first_stamp_ns = static_cast<int64_t>(rng_());
    m->last_stamp_ns = static_cast<int64_t>(rng_());
    m->images = static_cast<uint32_t>(rng_());
    m->distance_m = Real();
    m->octree_bytes = rng_();
    m->cloud_bytes = rng_();
  }
  void Fill(rover_msgs::GraphFactor* m) {
    Fill(&m->header);
    m->id = rng_();
    m->kind = static_cast<uint8_t>(Uniform(0, 5));
    m->key_a = Text(8);
    m->key_b = Text(8);
    FillArray(&m->p_a_b_m);
    FillArray(&m->q_a_b_wxyz);
    FillArray(&m->covariance);
    m->robust = Uniform(0, 1) == 1;
  }
  void Fill(rover_msgs::SubmapOrigin* m) {
    m->robot = static_cast<int32_t>(rng_());
    m->submap = static_cast<int64_t>(rng_());
    Fill(&m->pose);
    FillArray(&m->covariance);
  }
  void Fill(rover_msgs::SubmapOrigins* m) {
    Fill(&m->header);
    m->update = rng_();
    FillVector(&m->origins);
  }
  void Fill(rover_msgs::TagDetection* m) {
    Fill(&m->header);
    m->family = Text(8);
    m->id = static_cast<int32_t>(rng_());
    m->accepted = Uniform(0, 1) == 1;
    m->refusal = Text(20);
    FillArray(&m->corners_px);
    FillArray(&m->covariance);
    Fill(&m->pose);
    Fill(&m->alternative_pose);
    m->hamming = static_cast<int32_t>(Uniform(0, 3));
    m->flipped = static_cast<uint32_t>(Uniform(0, 256));
    m->decision_margin = Real();
    m->reprojection_rmse_px = Real();
    m->ambiguity_ratio = Real();
    m->distance_m = Real();
    m->tilt_rad = Real();
  }
  void Fill(rover_msgs::TeamMessage* m) {
    Fill(&m->header);
    m->origin = static_cast<int32_t>(rng_());
    m->stream = static_cast<uint8_t>(Uniform(0, 2));
    m->seq = rng_();
    FillOctets(&m->data);
  }
  void Fill(nav_msgs::Odometry* m) {
    Fill(&m->header);
    m->child_frame_id = FrameId::Truncated(Text(FrameId::kCapacity));
    Fill(&m->pose);
    Fill(&m->twist);
  }
  void Fill(tf2_msgs::TFMessage* m) { FillVector(&m->transforms); }
  void Fill(diagnostic_msgs::KeyValue* m) {
    m->key = Text(20);
    m->value = Text(40);
  }
  void Fill(diagnostic_msgs::DiagnosticStatus* m) {
    m->level = static_cast<uint8_t>(Uniform(0, 3));
    m->name = Text(20);
    m->message = Text(30);
    m->hardware_id = Text(9);
    FillVector(&m->values);
  }
  void Fill(diagnostic_msgs::DiagnosticArray* m) {
    Fill(&m->header);
    FillVector(&m->status);
  }
  void Fill(rover_msgs::LogChannelHealth* m) {
    m->topic = Text(24);
    m->records_written = rng_();
    m->records_dropped = rng_();
    m->ring_high_water = static_cast<uint32_t>(rng_());
  }
  void Fill(rover_msgs::LogHealth* m) {
    Fill(&m->header);
    m->records_written = rng_();
    m->bytes_written = rng_();
    FillVector(&m->channels);
  }
  void Fill(rover_msgs::EstimatorImu* m) {
    m->sequence = rng_();
    m->stamp_ns = static_cast<int64_t>(rng_());
    FillArray(&m->angular_velocity_rad_s);
    FillArray(&m->linear_acceleration_m_s2);
  }
  void Fill(rover_msgs::EstimatorEvent* m) {
    m->sequence = rng_();
    m->stamp_ns = static_cast<int64_t>(rng_());
    m->kind = static_cast<uint8_t>(Uniform(0, 2));
    m->request_id = rng_();
  }
  void Fill(rover_msgs::EstimatorRelativePose* m) {
    m->sequence = rng_();
    m->stamp_ns = static_cast<int64_t>(rng_());
    m->from_stamp_ns = static_cast<int64_t>(rng_());
    m->to_stamp_ns = static_cast<int64_t>(rng_());
    FillArray(&m->p_from_to_m);
    FillArray(&m->q_from_to_xyzw);
    FillArray(&m->covariance);
    m->to_is_keyframe = Uniform(0, 1) == 1;
    m->oldest_keyframe_stamp_ns = static_cast<int64_t>(rng_());
  }
  void Fill(rover_msgs::EstimatorWheelSpeeds* m) {
    m->sequence = rng_();
    m->stamp_ns = static_cast<int64_t>(rng_());
    FillArray(&m->wheel_rate_rad_s);
  }
  void Fill(rover_msgs::EstimatorState* m) {
    m->sequence = rng_();
    m->stamp_ns = static_cast<int64_t>(rng_());
    m->frame_id = static_cast<uint32_t>(rng_());
    m->status = static_cast<uint32_t>(rng_());
    FillArray(&m->p_local_body_m);
    FillArray(&m->v_local_m_s);
    FillArray(&m->q_local_body_xyzw);
    FillArray(&m->accel_bias_m_s2);
    FillArray(&m->gyro_bias_rad_s);
    FillArray(&m->angular_velocity_body_rad_s);
    FillArray(&m->covariance);
  }
  void Fill(rover_msgs::EstimatorFrameSwitch* m) {
    m->sequence = rng_();
    m->stamp_ns = static_cast<int64_t>(rng_());
    m->old_frame_id = static_cast<uint32_t>(rng_());
    m->new_frame_id = static_cast<uint32_t>(rng_());
    FillArray(&m->p_old_new_m);
    m->yaw_old_new_rad = Real();
    FillArray(&m->covariance);
  }

 private:
  int64_t Uniform(int64_t lo, int64_t hi) {
    return std::uniform_int_distribution<int64_t>(lo, hi)(rng_);
  }

  // Mostly ordinary values, sometimes ones that stress the encoding. No NaN,
  // so decoded messages can be compared with ==.
  double Real() {
    switch (Uniform(0, 9)) {
      case 0:
        return std::numeric_limits<double>::infinity();
      case 1:
        return -0.0;
      case 2:
        return std::numeric_limits<double>::denorm_min();
      case 3:
        return -std::numeric_limits<double>::max();
      default:
        return std::uniform_real_distribution<double>(-1e3, 1e3)(rng_);
    }
  }

  // Random length in [0, max_size] so that every alignment case after a
  // string occurs; printable ASCII plus some UTF-8.
  std::string Text(size_t max_size) {
    std::string s(static_cast<size_t>(Uniform(0, static_cast<int64_t>(max_size))), 'x');
    for (char& c : s) c = static_cast<char>(Uniform(0x20, 0x7e));
    if (!s.empty() && Uniform(0, 3) == 0) s.back() = static_cast<char>(0xC3);  // Lone lead byte.
    return s;
  }

  template <size_t N>
  void FillArray(std::array<double, N>* values) {
    for (double& v : *values) v = Real();
  }

  // 0..67 octets: every alignment of what follows.
  template <typename Octet>
  void FillOctets(std::vector<Octet>* values) {
    values->resize(static_cast<size_t>(Uniform(0, 67)));
    for (Octet& b : *values) b = static_cast<Octet>(rng_());
  }

  template <typename T>
  void FillVector(std::vector<T>* values) {
    values->resize(static_cast<size_t>(Uniform(0, 4)));
    for (T& v : *values) Fill(&v);
  }

  std::mt19937_64 rng_;
};

/// Every registered message type, for typed tests.
using AllMessageTypes = ::testing::Types<
    builtin_interfaces::Time, std_msgs::Header, geometry_msgs::Vector3, geometry_msgs::Point,
    geometry_msgs::Quaternion, geometry_msgs::Pose, geometry_msgs::PoseWithCovariance,
    geometry_msgs::PoseWithCovarianceStamped, geometry_msgs::Twist,
    geometry_msgs::TwistWithCovariance, geometry_msgs::Transform, geometry_msgs::TransformStamped,
    sensor_msgs::Imu, sensor_msgs::Image, sensor_msgs::PointField, sensor_msgs::PointCloud2,
    nav_msgs::Odometry, nav_msgs::MapMetaData, nav_msgs::OccupancyGrid, octomap_msgs::Octomap,
    tf2_msgs::TFMessage, diagnostic_msgs::KeyValue, diagnostic_msgs::DiagnosticStatus,
    diagnostic_msgs::DiagnosticArray, rover_msgs::LogChannelHealth, rover_msgs::LogHealth,
    rover_msgs::EstimatorImu, rover_msgs::EstimatorEvent, rover_msgs::EstimatorRelativePose,
    rover_msgs::EstimatorWheelSpeeds, rover_msgs::EstimatorState, rover_msgs::EstimatorFrameSwitch,
    rover_msgs::SubmapInfo, rover_msgs::GraphFactor, rover_msgs::SubmapOrigin,
    rover_msgs::SubmapOrigins, rover_msgs::TagDetection, rover_msgs::TeamMessage>;

/// gtest names for AllMessageTypes instances: the ROS type name.
struct MessageTypeName {
  template <typename T>
  static std::string GetName(int) {
    std::string name(MessageTraits<T>::kName);
    for (char& c : name) {
      if (c == '/') c = '_';
    }
    return name;
  }
};

}  // namespace rover::log::cdr_test

#endif  // ROVER_TESTS_CORE_LOG_CDR_RANDOM_MSGS_H_
