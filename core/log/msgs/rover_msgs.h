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

void Serialize(const LogChannelHealth& msg, CdrWriter& writer);
void Serialize(const LogHealth& msg, CdrWriter& writer);
void Serialize(const SubmapInfo& msg, CdrWriter& writer);
bool Deserialize(CdrReader& reader, LogChannelHealth* msg);
bool Deserialize(CdrReader& reader, LogHealth* msg);
bool Deserialize(CdrReader& reader, SubmapInfo* msg);

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

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_MSGS_ROVER_MSGS_H_
