#include "core/log/msgs/all_msgs.h"

#include <array>

namespace rover::log {
namespace {

template <typename T>
constexpr MessageSchema SchemaOf() {
  return {MessageTraits<T>::kName, &MessageTraits<T>::Definition};
}

constexpr std::array kAllSchemas = {
    SchemaOf<builtin_interfaces::Time>(),
    SchemaOf<std_msgs::Header>(),
    SchemaOf<geometry_msgs::Vector3>(),
    SchemaOf<geometry_msgs::Point>(),
    SchemaOf<geometry_msgs::Quaternion>(),
    SchemaOf<geometry_msgs::Pose>(),
    SchemaOf<geometry_msgs::PoseWithCovariance>(),
    SchemaOf<geometry_msgs::PoseWithCovarianceStamped>(),
    SchemaOf<geometry_msgs::Twist>(),
    SchemaOf<geometry_msgs::TwistWithCovariance>(),
    SchemaOf<geometry_msgs::Transform>(),
    SchemaOf<geometry_msgs::TransformStamped>(),
    SchemaOf<sensor_msgs::Imu>(),
    SchemaOf<sensor_msgs::Image>(),
    SchemaOf<sensor_msgs::PointField>(),
    SchemaOf<sensor_msgs::PointCloud2>(),
    SchemaOf<nav_msgs::Odometry>(),
    SchemaOf<nav_msgs::MapMetaData>(),
    SchemaOf<nav_msgs::OccupancyGrid>(),
    SchemaOf<octomap_msgs::Octomap>(),
    SchemaOf<tf2_msgs::TFMessage>(),
    SchemaOf<diagnostic_msgs::KeyValue>(),
    SchemaOf<diagnostic_msgs::DiagnosticStatus>(),
    SchemaOf<diagnostic_msgs::DiagnosticArray>(),
    SchemaOf<rover_msgs::LogChannelHealth>(),
    SchemaOf<rover_msgs::LogHealth>(),
    SchemaOf<rover_msgs::EstimatorImu>(),
    SchemaOf<rover_msgs::EstimatorEvent>(),
    SchemaOf<rover_msgs::EstimatorRelativePose>(),
    SchemaOf<rover_msgs::EstimatorWheelSpeeds>(),
    SchemaOf<rover_msgs::EstimatorState>(),
    SchemaOf<rover_msgs::EstimatorFrameSwitch>(),
    SchemaOf<rover_msgs::SubmapInfo>(),
    SchemaOf<rover_msgs::GraphFactor>(),
    SchemaOf<rover_msgs::SubmapOrigin>(),
    SchemaOf<rover_msgs::SubmapOrigins>(),
    SchemaOf<rover_msgs::TagDetection>(),
    SchemaOf<rover_msgs::TeamMessage>(),
};

}  // namespace

std::span<const MessageSchema> AllMessageSchemas() { return kAllSchemas; }

}  // namespace rover::log
