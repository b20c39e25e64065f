#include "core/log/msgs/definitions.h"

#include <algorithm>
#include <array>

namespace rover::log::internal {
namespace {

struct OwnText {
  std::string_view type;  // "pkg/Type"
  std::string_view text;  // Field and constant lines, '\n'-separated, no trailing newline.
};

// Field types, names, order, defaults and constants follow the ROS 2 Humble
// .msg files (comments omitted). A reader decodes our CDR bytes by walking
// these texts, so any divergence from the real definitions corrupts decoding.
// Types from the same package are written unqualified, as in the originals.
constexpr std::array kOwnTexts = {
    OwnText{"builtin_interfaces/Time",
            "int32 sec\n"
            "uint32 nanosec"},
    OwnText{"std_msgs/Header",
            "builtin_interfaces/Time stamp\n"
            "string frame_id"},
    OwnText{"geometry_msgs/Vector3",
            "float64 x\n"
            "float64 y\n"
            "float64 z"},
    OwnText{"geometry_msgs/Point",
            "float64 x\n"
            "float64 y\n"
            "float64 z"},
    OwnText{"geometry_msgs/Quaternion",
            "float64 x 0\n"
            "float64 y 0\n"
            "float64 z 0\n"
            "float64 w 1"},
    OwnText{"geometry_msgs/Pose",
            "Point position\n"
            "Quaternion orientation"},
    OwnText{"geometry_msgs/PoseWithCovariance",
            "Pose pose\n"
            "float64[36] covariance"},
    OwnText{"geometry_msgs/PoseWithCovarianceStamped",
            "std_msgs/Header header\n"
            "PoseWithCovariance pose"},
    OwnText{"geometry_msgs/Twist",
            "Vector3 linear\n"
            "Vector3 angular"},
    OwnText{"geometry_msgs/TwistWithCovariance",
            "Twist twist\n"
            "float64[36] covariance"},
    OwnText{"geometry_msgs/Transform",
            "Vector3 translation\n"
            "Quaternion rotation"},
    OwnText{"geometry_msgs/TransformStamped",
            "std_msgs/Header header\n"
            "string child_frame_id\n"
            "Transform transform"},
    OwnText{"sensor_msgs/Imu",
            "std_msgs/Header header\n"
            "geometry_msgs/Quaternion orientation\n"
            "float64[9] orientation_covariance\n"
            "geometry_msgs/Vector3 angular_velocity\n"
            "float64[9] angular_velocity_covariance\n"
            "geometry_msgs/Vector3 linear_acceleration\n"
            "float64[9] linear_acceleration_covariance"},
    OwnText{"sensor_msgs/Image",
            "std_msgs/Header header\n"
            "uint32 height\n"
            "uint32 width\n"
            "string encoding\n"
            "uint8 is_bigendian\n"
            "uint32 step\n"
            "uint8[] data"},
    OwnText{"sensor_msgs/PointField",
            "uint8 INT8=1\n"
            "uint8 UINT8=2\n"
            "uint8 INT16=3\n"
            "uint8 UINT16=4\n"
            "uint8 INT32=5\n"
            "uint8 UINT32=6\n"
            "uint8 FLOAT32=7\n"
            "uint8 FLOAT64=8\n"
            "string name\n"
            "uint32 offset\n"
            "uint8 datatype\n"
            "uint32 count"},
    OwnText{"sensor_msgs/PointCloud2",
            "std_msgs/Header header\n"
            "uint32 height\n"
            "uint32 width\n"
            "PointField[] fields\n"
            "bool is_bigendian\n"
            "uint32 point_step\n"
            "uint32 row_step\n"
            "uint8[] data\n"
            "bool is_dense"},
    OwnText{"nav_msgs/MapMetaData",
            "builtin_interfaces/Time map_load_time\n"
            "float32 resolution\n"
            "uint32 width\n"
            "uint32 height\n"
            "geometry_msgs/Pose origin"},
    OwnText{"nav_msgs/OccupancyGrid",
            "std_msgs/Header header\n"
            "MapMetaData info\n"
            "int8[] data"},
    OwnText{"octomap_msgs/Octomap",
            "std_msgs/Header header\n"
            "bool binary\n"
            "string id\n"
            "float64 resolution\n"
            "int8[] data"},
    OwnText{"nav_msgs/Odometry",
            "std_msgs/Header header\n"
            "string child_frame_id\n"
            "geometry_msgs/PoseWithCovariance pose\n"
            "geometry_msgs/TwistWithCovariance twist"},
    OwnText{"tf2_msgs/TFMessage", "geometry_msgs/TransformStamped[] transforms"},
    OwnText{"diagnostic_msgs/KeyValue",
            "string key\n"
            "string value"},
    OwnText{"diagnostic_msgs/DiagnosticStatus",
            "byte OK=0\n"
            "byte WARN=1\n"
            "byte ERROR=2\n"
            "byte STALE=3\n"
            "byte level\n"
            "string name\n"
            "string message\n"
            "string hardware_id\n"
            "KeyValue[] values"},
    OwnText{"diagnostic_msgs/DiagnosticArray",
            "std_msgs/Header header\n"
            "DiagnosticStatus[] status"},
    // The project's own types: see core/log/msgs/rover_msgs.h for semantics.
    OwnText{"rover_msgs/LogChannelHealth",
            "string topic\n"
            "uint64 records_written\n"
            "uint64 records_dropped\n"
            "uint32 ring_high_water"},
    OwnText{"rover_msgs/LogHealth",
            "std_msgs/Header header\n"
            "uint64 records_written\n"
            "uint64 bytes_written\n"
            "LogChannelHealth[] channels"},
    OwnText{"rover_msgs/EstimatorImu",
            "uint64 sequence\n"
            "int64 stamp_ns\n"
            "float64[3] angular_velocity_rad_s\n"
            "float64[3] linear_acceleration_m_s2"},
    OwnText{"rover_msgs/EstimatorEvent",
            "uint8 CLONE_TRIGGER=0\n"
            "uint8 FRAME_SWITCH_REQUEST=1\n"
            "uint8 POSE_REPORT_REQUEST=2\n"
            "uint64 sequence\n"
            "int64 stamp_ns\n"
            "uint8 kind\n"
            "uint64 request_id"},
    OwnText{"rover_msgs/EstimatorRelativePose",
            "uint64 sequence\n"
            "int64 stamp_ns\n"
            "int64 from_stamp_ns\n"
            "int64 to_stamp_ns\n"
            "float64[3] p_from_to_m\n"
            "float64[4] q_from_to_xyzw\n"
            "float64[36] covariance\n"
            "bool to_is_keyframe\n"
            "int64 oldest_keyframe_stamp_ns"},
    OwnText{"rover_msgs/EstimatorWheelSpeeds",
            "uint64 sequence\n"
            "int64 stamp_ns\n"
            "float64[4] wheel_rate_rad_s"},
    OwnText{"rover_msgs/EstimatorState",
            "uint64 sequence\n"
            "int64 stamp_ns\n"
            "uint32 frame_id\n"
            "uint32 status\n"
            "float64[3] p_local_body_m\n"
            "float64[3] v_local_m_s\n"
            "float64[4] q_local_body_xyzw\n"
            "float64[3] accel_bias_m_s2\n"
            "float64[3] gyro_bias_rad_s\n"
            "float64[3] angular_velocity_body_rad_s\n"
            "float64[225] covariance"},
    OwnText{"rover_msgs/EstimatorFrameSwitch",
            "uint64 sequence\n"
            "int64 stamp_ns\n"
            "uint32 old_frame_id\n"
            "uint32 new_frame_id\n"
            "float64[3] p_old_new_m\n"
            "float64 yaw_old_new_rad\n"
            "float64[16] covariance"},
    OwnText{"rover_msgs/SubmapInfo",
            "std_msgs/Header header\n"
            "uint32 index\n"
            "uint32 frame_id\n"
            "bool has_origin\n"
            "uint32 previous_frame_id\n"
            "int64 origin_stamp_ns\n"
            "float64[3] p_previous_origin_m\n"
            "float64 yaw_previous_origin_rad\n"
            "float64[16] origin_covariance\n"
            "int64 first_stamp_ns\n"
            "int64 last_stamp_ns\n"
            "uint32 images\n"
            "float64 distance_m\n"
            "uint64 octree_bytes\n"
            "uint64 cloud_bytes"},
    OwnText{"rover_msgs/GraphFactor",
            "uint8 PRIOR=0\n"
            "uint8 FRAME_SWITCH=1\n"
            "uint8 FILTER_POSE=2\n"
            "uint8 SUBMAP_MATCH=3\n"
            "uint8 ROBOT_DETECTION=4\n"
            "uint8 LANDMARK_OBSERVATION=5\n"
            "std_msgs/Header header\n"
            "uint64 id\n"
            "uint8 kind\n"
            "string key_a\n"
            "string key_b\n"
            "float64[3] p_a_b_m\n"
            "float64[4] q_a_b_wxyz\n"
            "float64[36] covariance\n"
            "bool robust"},
    OwnText{"rover_msgs/SubmapOrigin",
            "int32 robot\n"
            "int64 submap\n"
            "geometry_msgs/Pose pose\n"
            "float64[36] covariance"},
    OwnText{"rover_msgs/SubmapOrigins",
            "std_msgs/Header header\n"
            "uint64 update\n"
            "SubmapOrigin[] origins"},
    OwnText{"rover_msgs/TagDetection",
            "std_msgs/Header header\n"
            "string family\n"
            "int32 id\n"
            "bool accepted\n"
            "string refusal\n"
            "float64[8] corners_px\n"
            "float64 decision_margin\n"
            "int32 hamming\n"
            "geometry_msgs/Pose pose\n"
            "geometry_msgs/Pose alternative_pose\n"
            "float64 reprojection_rmse_px\n"
            "float64 ambiguity_ratio\n"
            "float64 distance_m\n"
            "float64 tilt_rad\n"
            "float64[36] covariance\n"
            "uint32 flipped"},
    OwnText{"rover_msgs/TeamMessage",
            "std_msgs/Header header\n"
            "int32 origin\n"
            "uint8 stream\n"
            "uint64 seq\n"
            "uint8[] data"},
};

// The primitive types of the ROS 2 interface definition language.
constexpr std::array<std::string_view, 17> kPrimitiveTypes = {
    "bool",  "byte",   "char",  "float32", "float64", "int8",    "uint8", "int16",   "uint16",
    "int32", "uint32", "int64", "uint64",  "string",  "wstring", "time",  "duration"};

// "pkg/msg/Type" -> "pkg/Type"; other spellings are returned unchanged.
std::string NormalizeName(std::string_view type) {
  const size_t first = type.find('/');
  const size_t last = type.rfind('/');
  if (first != std::string_view::npos && last != first &&
      type.substr(first, last - first) == "/msg") {
    std::string result(type.substr(0, first));
    result += type.substr(last);
    return result;
  }
  return std::string(type);
}

std::string_view Trim(std::string_view s) {
  const size_t begin = s.find_first_not_of(" \t\r");
  if (begin == std::string_view::npos) return {};
  const size_t end = s.find_last_not_of(" \t\r");
  return s.substr(begin, end - begin + 1);
}

void AppendClosure(std::string_view type, std::vector<std::string>* seen, std::string* out) {
  for (const std::string& dependency : DirectDependencies(type)) {
    if (std::find(seen->begin(), seen->end(), dependency) != seen->end()) continue;
    seen->push_back(dependency);
    *out += '\n';
    out->append(80, '=');
    *out += "\nMSG: ";
    *out += dependency;
    *out += '\n';
    *out += OwnDefinition(dependency);
    AppendClosure(dependency, seen, out);
  }
}

}  // namespace

std::string_view OwnDefinition(std::string_view type) {
  const std::string name = NormalizeName(type);
  for (const OwnText& entry : kOwnTexts) {
    if (entry.type == name) return entry.text;
  }
  return {};
}

std::vector<std::string> DirectDependencies(std::string_view type) {
  const std::string name = NormalizeName(type);
  const std::string_view package = std::string_view(name).substr(0, name.find('/'));
  std::vector<std::string> dependencies;
  std::string_view text = OwnDefinition(name);
  while (!text.empty()) {
    const size_t newline = text.find('\n');
    std::string_view line = text.substr(0, newline);
    text = newline == std::string_view::npos ? std::string_view{} : text.substr(newline + 1);
    line = Trim(line.substr(0, line.find('#')));
    if (line.empty()) continue;
    // The type is the first token, minus any array suffix ("[]", "[9]",
    // "[<=4]") or string bound ("<=8").
    std::string_view field_type = line.substr(0, line.find_first_of(" \t"));
    field_type = field_type.substr(0, field_type.find_first_of("[<"));
    if (std::find(kPrimitiveTypes.begin(), kPrimitiveTypes.end(), field_type) !=
        kPrimitiveTypes.end()) {
      continue;
    }
    if (field_type.find('/') == std::string_view::npos) {
      std::string qualified(package);
      qualified += '/';
      qualified += field_type;
      dependencies.push_back(std::move(qualified));
    } else {
      dependencies.push_back(NormalizeName(field_type));
    }
  }
  return dependencies;
}

std::string ComposeDefinition(std::string_view type) {
  std::string out(OwnDefinition(type));
  std::vector<std::string> seen = {NormalizeName(type)};
  AppendClosure(type, &seen, &out);
  return out;
}

}  // namespace rover::log::internal
