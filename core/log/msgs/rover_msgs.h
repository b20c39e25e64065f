#ifndef ROVER_CORE_LOG_MSGS_ROVER_MSGS_H_
#define ROVER_CORE_LOG_MSGS_ROVER_MSGS_H_

// rover_msgs: the project's own message types.

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
namespace rover_msgs {

/// rover_msgs/msg/LogChannelHealth: counters of one logged topic.
struct LogChannelHealth {
  std::string topic;
  uint64_t records_written = 0;  // Records that reached the file.
  uint64_t records_dropped = 0;  // Records lost, e.g. to a full ring.
  uint32_t ring_high_water = 0;  // Most records ever queued in the channel's ring.

  friend bool operator==(const LogChannelHealth&, const LogChannelHealth&) = default;
};

/// rover_msgs/msg/LogHealth: the flight log's periodic self-report, written
/// into the log itself so a file documents its own completeness.
struct LogHealth {
  std_msgs::Header header;
  uint64_t records_written = 0;  // Over all channels, since the log was opened.
  uint64_t bytes_written = 0;    // File bytes, since the log was opened.
  std::vector<LogChannelHealth> channels;

  friend bool operator==(const LogHealth&, const LogHealth&) = default;
};

/// rover_msgs/msg/SubmapInfo: one finished submap as mapd logged it. The
/// submap lives in the estimator's local frame `frame_id` (header.frame_id is
/// "local/<robot>/<frame_id>"); its origin is the frame switch that opened
/// it (graph factor w: previous frame -> this one, x y z yaw and their 4x4
/// covariance), absent when mapd joined a frame already running. The octree
/// and cloud travel as octomap_msgs/Octomap and sensor_msgs/PointCloud2 with
/// the same header; their serialised sizes are counted here.
struct SubmapInfo {
  std_msgs::Header header;
  uint32_t index = 0;
  uint32_t frame_id = 0;
  bool has_origin = false;
  uint32_t previous_frame_id = 0;
  int64_t origin_stamp_ns = 0;
  std::array<double, 3> p_previous_origin_m{};
  double yaw_previous_origin_rad = 0.0;
  std::array<double, 16> origin_covariance{};
  int64_t first_stamp_ns = 0;
  int64_t last_stamp_ns = 0;
  uint32_t images = 0;
  double distance_m = 0.0;
  uint64_t octree_bytes = 0;
  uint64_t cloud_bytes = 0;

  friend bool operator==(const SubmapInfo&, const SubmapInfo&) = default;
};

/// rover_msgs/msg/GraphFactor: one factor of the rover's pose graph, as mapd
/// added it (mapd logs every factor when it adds it, so a restarted mapd, or
/// `rover-graph` offline, rebuilds the same graph from the log). Keys are
/// GraphKey names ("s0_3": origin 3 of robot 0; "x0_17"; "l4"); `key_b` is
/// empty for a prior. The measurement is T_a_b (for a prior T_world_a); the
/// covariance is row-major over [dp (m, frame a); dtheta (rad, right)]. For a
/// frame switch (kind W) only rows/columns 0, 1, 2, 5 are used: the filter's
/// 4x4 over [dp; dyaw]. `id` counts the robot's factors from 1, so the same
/// factor read twice (two logs of one mission) is recognised.
struct GraphFactor {
  static constexpr uint8_t kPrior = 0;
  static constexpr uint8_t kFrameSwitch = 1;          ///< w
  static constexpr uint8_t kFilterPose = 2;           ///< v
  static constexpr uint8_t kSubmapMatch = 3;          ///< c
  static constexpr uint8_t kRobotDetection = 4;       ///< d
  static constexpr uint8_t kLandmarkObservation = 5;  ///< o
  std_msgs::Header header;
  uint64_t id = 0;
  uint8_t kind = kPrior;
  std::string key_a;
  std::string key_b;
  std::array<double, 3> p_a_b_m{};
  std::array<double, 4> q_a_b_wxyz{1.0, 0.0, 0.0, 0.0};
  std::array<double, 36> covariance{};
  bool robust = false;

  friend bool operator==(const GraphFactor&, const GraphFactor&) = default;
};

/// rover_msgs/msg/SubmapOrigin: one optimised submap origin T_world_origin
/// with its marginal covariance (row-major, [dt (m, world); dphi (rad,
/// right)]; all zero when not computed).
struct SubmapOrigin {
  int32_t robot = 0;
  int64_t submap = 0;
  geometry_msgs::Pose pose;
  std::array<double, 36> covariance{};

  friend bool operator==(const SubmapOrigin&, const SubmapOrigin&) = default;
};

/// rover_msgs/msg/SubmapOrigins: every submap origin after one update of the
/// pose graph (header.frame_id "world"; stamp: the newest input's).
struct SubmapOrigins {
  std_msgs::Header header;
  uint64_t update = 0;  ///< counts the graph's updates from 1
  std::vector<SubmapOrigin> origins;

  friend bool operator==(const SubmapOrigins&, const SubmapOrigins&) = default;
};

/// rover_msgs/msg/TagDetection: one decoded AprilTag in a rectified image,
/// accepted for the graph or refused with the reason (header.stamp: the
/// image's capture; header.frame_id: the rectified camera, "cam0"). Corners
/// x0 y0 .. x3 y3 in the library's order, OpenCV pixel centres. `pose` is
/// the better of the two solutions of the planar ambiguity (T_camera_tag),
/// `alternative_pose` the other; the covariance is row-major over [dt (m,
/// camera); dtheta (rad, tag frame, right)], zero when refused before the
/// error model. `flipped`: perturbed corner sets (of 256) whose pose fell on
/// the other solution.
struct TagDetection {
  std_msgs::Header header;
  std::string family;
  int32_t id = 0;
  bool accepted = false;
  std::string refusal;
  std::array<double, 8> corners_px{};
  double decision_margin = 0.0;
  int32_t hamming = 0;
  geometry_msgs::Pose pose;
  geometry_msgs::Pose alternative_pose;
  double reprojection_rmse_px = 0.0;
  double ambiguity_ratio = 0.0;
  double distance_m = 0.0;
  double tilt_rad = 0.0;
  std::array<double, 36> covariance{};
  uint32_t flipped = 0;

  friend bool operator==(const TagDetection&, const TagDetection&) = default;
};

/// rover_msgs/msg/TeamMessage: one message of the team link as it travelled
/// (sent by this rover, or received from another), so that a restarted mapd
/// carries on where it stopped and the mission can be replayed from the log.
/// header.stamp: when it was sent or received (CLOCK_MONOTONIC of the
/// logging rover); `origin`: the robot that published it; `stream` and `seq`
/// name it within the origin's messages (seq from 1); `data`: its bytes.
struct TeamMessage {
  std_msgs::Header header;
  int32_t origin = 0;
  uint8_t stream = 0;
  uint64_t seq = 0;
  std::vector<uint8_t> data;

  friend bool operator==(const TeamMessage&, const TeamMessage&) = default;
};

void Serialize(const LogChannelHealth& msg, CdrWriter& writer);
void Serialize(const LogHealth& msg, CdrWriter& writer);
void Serialize(const SubmapInfo& msg, CdrWriter& writer);
bool Deserialize(CdrReader& reader, LogChannelHealth* msg);
bool Deserialize(CdrReader& reader, LogHealth* msg);
bool Deserialize(CdrReader& reader, SubmapInfo* msg);
void Serialize(const GraphFactor& msg, CdrWriter& writer);
void Serialize(const SubmapOrigin& msg, CdrWriter& writer);
void Serialize(const SubmapOrigins& msg, CdrWriter& writer);
bool Deserialize(CdrReader& reader, GraphFactor* msg);
bool Deserialize(CdrReader& reader, SubmapOrigin* msg);
bool Deserialize(CdrReader& reader, SubmapOrigins* msg);
void Serialize(const TagDetection& msg, CdrWriter& writer);
bool Deserialize(CdrReader& reader, TagDetection* msg);
void Serialize(const TeamMessage& msg, CdrWriter& writer);
bool Deserialize(CdrReader& reader, TeamMessage* msg);

}  // namespace rover_msgs

template <>
struct MessageTraits<rover_msgs::LogChannelHealth> {
  static constexpr std::string_view kName = "rover_msgs/msg/LogChannelHealth";
  static std::string_view Definition();
};

template <>
struct MessageTraits<rover_msgs::LogHealth> {
  static constexpr std::string_view kName = "rover_msgs/msg/LogHealth";
  static std::string_view Definition();
};

template <>
struct MessageTraits<rover_msgs::SubmapInfo> {
  static constexpr std::string_view kName = "rover_msgs/msg/SubmapInfo";
  static std::string_view Definition();
};

template <>
struct MessageTraits<rover_msgs::GraphFactor> {
  static constexpr std::string_view kName = "rover_msgs/msg/GraphFactor";
  static std::string_view Definition();
};

template <>
struct MessageTraits<rover_msgs::SubmapOrigin> {
  static constexpr std::string_view kName = "rover_msgs/msg/SubmapOrigin";
  static std::string_view Definition();
};

template <>
struct MessageTraits<rover_msgs::SubmapOrigins> {
  static constexpr std::string_view kName = "rover_msgs/msg/SubmapOrigins";
  static std::string_view Definition();
};

template <>
struct MessageTraits<rover_msgs::TeamMessage> {
  static constexpr std::string_view kName = "rover_msgs/msg/TeamMessage";
  static std::string_view Definition();
};

template <>
struct MessageTraits<rover_msgs::TagDetection> {
  static constexpr std::string_view kName = "rover_msgs/msg/TagDetection";
  static std::string_view Definition();
};

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_MSGS_ROVER_MSGS_H_
