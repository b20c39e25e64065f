#include "estimator/eval/mcap_trajectory.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <set>

#include "core/log/mcap/mcap_reader.h"
#include "core/log/msgs/geometry_msgs.h"
#include "core/log/msgs/message_traits.h"
#include "core/log/msgs/nav_msgs.h"
#include "estimator/eval/eval_error.h"
#include "estimator/eval/number_format.h"

namespace rover::eval {
namespace {

using log::geometry_msgs::PoseWithCovarianceStamped;
using log::geometry_msgs::TransformStamped;
using log::nav_msgs::Odometry;

// A decoded pose message, still in its own local frame.
struct LocalPose {
  uint64_t index = 0;  // Message number on the topic (1-based), for errors.
  Time stamp;
  std::string frame_id;
  Eigen::Vector3d p_frame_body = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_frame_body = Eigen::Quaterniond::Identity();
  std::optional<Matrix6d> covariance;
  std::optional<Eigen::Vector3d> v_body_m_s;
};

Eigen::Quaterniond ToEigen(const log::geometry_msgs::Quaternion& q) {
  return Eigen::Quaterniond(q.w, q.x, q.y, q.z);
}

std::optional<Matrix6d> CovarianceOf(const std::array<double, 36>& c) {
  // ROS marks an unknown covariance with -1 in the first element; all zeros
  // means the publisher did not fill it.
  if (c[0] < 0.0) return std::nullopt;
  if (std::all_of(c.begin(), c.end(), [](double v) { return v == 0.0; })) return std::nullopt;
  Matrix6d P;
  for (int r = 0; r < 6; ++r) {
    for (int col = 0; col < 6; ++col) P(r, col) = c[static_cast<std::size_t>(6 * r + col)];
  }
  return P;
}

class MessageContext {
 public:
  MessageContext(const std::string& path, const std::string& topic, uint64_t index,
                 uint64_t log_time)
      : path_(path), topic_(topic), index_(index), log_time_(log_time) {}

  [[noreturn]] void Fail(const std::string& what) const {
    throw EvalError(
        path_ + ": message " + std::to_string(index_) + " on " + topic_ + " (log time " +
        FormatSeconds(Time::FromNanoseconds(static_cast<int64_t>(log_time_))) + " s): " + what);
  }

  /// Checks a pose and returns its quaternion at unit norm.
  Eigen::Quaterniond CheckPose(const Eigen::Vector3d& p, const Eigen::Quaterniond& q) const {
    if (!p.allFinite() || !q.coeffs().allFinite()) {
      Fail("expected a finite pose, found a NaN or infinite value");
    }
    const double norm = q.norm();
    if (std::abs(norm - 1.0) > 1e-3) {
      Fail("expected a unit quaternion (norm 1 +- 1e-3), found norm " + FormatDouble(norm));
    }
    return UnitQuaternion(q);
  }

 private:
  const std::string& path_;
  const std::string& topic_;
  uint64_t index_;
  uint64_t log_time_;
};

template <typename T>
T Decode(const log::MessageView& m, const MessageContext& context) {
  T msg;
  std::string error;
  if (!log::DeserializeMessage(m.data, &msg, &error)) {
    context.Fail("expected a valid CDR " + std::string(log::MessageTraits<T>::kName) +
                 ", found: " + error);
  }
  return msg;
}

std::string TopicList(const log::McapReader& reader) {
  std::set<std::string> topics;
  for (const auto& [id, channel] : reader.channels()) topics.insert(channel.topic);
  if (topics.empty()) return "no channels";
  std::string list;
  for (const std::string& t : topics) list += (list.empty() ? "" : ", ") + t;
  return list;
}

// Channel ids on `topic` and their common schema name.
std::vector<uint16_t> ChannelsOf(const log::McapReader& reader, const std::string& topic,
                                 std::string* schema_name) {
  std::vector<uint16_t> ids;
  for (const auto& [id, channel] : reader.channels()) {
    if (channel.topic != topic) continue;
    const auto schema = reader.schemas().find(channel.schema_id);
    const std::string name = schema == reader.schemas().end() ? "" : schema->second.name;
    if (!ids.empty() && name != *schema_name) {
      throw EvalError("topic " + topic + " has channels of two message types (" + *schema_name +
                      ", " + name + ")");
    }
    *schema_name = name;
    ids.push_back(id);
  }
  return ids;
}

// Resolves T_root_frame for every frame reachable from `root` through the
// switches, in either direction.
std::map<std::string, Eigen::Isometry3d> ChainFrames(const std::string& root,
                                                     const std::vector<FrameSwitch>& switches) {
  std::map<std::string, Eigen::Isometry3d> T_root;
  T_root.emplace(root, Eigen::Isometry3d::Identity());
  std::vector<bool> done(switches.size(), false);
  for (bool progress = true; progress;) {
    progress = false;
    for (std::size_t i = 0; i < switches.size(); ++i) {
      if (done[i]) continue;
      const FrameSwitch& s = switches[i];
      const auto old_it = T_root.find(s.old_frame_id);
      const auto new_it = T_root.find(s.new_frame_id);
      if (old_it != T_root.end() && new_it != T_root.end()) {
        done[i] = true;  // Both known already (e.g. a loop back); keep the first chain.
        continue;
      }
      if (old_it != T_root.end()) {
        T_root.emplace(s.new_frame_id, old_it->second * s.T_old_new);
      } else if (new_it != T_root.end()) {
        T_root.emplace(s.old_frame_id, new_it->second * s.T_old_new.inverse());
      } else {
        continue;
      }
      done[i] = true;
      progress = true;
    }
  }
  return T_root;
}

}  // namespace

McapTrajectory ReadMcapTrajectory(const std::string& path, const McapTrajectoryOptions& options) {
  std::optional<log::McapReader> opened;
  try {
    opened.emplace(log::McapReader::Open(path));
  } catch (const std::exception& e) {
    throw EvalError(path + ": expected an MCAP flight log, found: " + e.what());
  }
  log::McapReader& reader = *opened;

  std::string pose_schema;
  const std::vector<uint16_t> pose_channels = ChannelsOf(reader, options.topic, &pose_schema);
  if (pose_channels.empty()) {
    throw EvalError(path + ": expected a channel on topic '" + options.topic +
                    "', found topics: " + TopicList(reader));
  }
  const bool is_odometry = pose_schema == log::MessageTraits<Odometry>::kName;
  const bool is_pose = pose_schema == log::MessageTraits<PoseWithCovarianceStamped>::kName;
  if (!is_odometry && !is_pose) {
    throw EvalError(path + ": expected " + std::string(log::MessageTraits<Odometry>::kName) +
                    " or " + std::string(log::MessageTraits<PoseWithCovarianceStamped>::kName) +
                    " on topic " + options.topic + ", found '" + pose_schema + "'");
  }
  std::string switch_schema;
  const std::vector<uint16_t> switch_channels =
      options.frame_switch_topic.empty()
          ? std::vector<uint16_t>{}
          : ChannelsOf(reader, options.frame_switch_topic, &switch_schema);
  if (!switch_channels.empty() && switch_schema != log::MessageTraits<TransformStamped>::kName) {
    throw EvalError(path + ": expected " +
                    std::string(log::MessageTraits<TransformStamped>::kName) + " on topic " +
                    options.frame_switch_topic + ", found '" + switch_schema + "'");
  }

  McapTrajectory result;
  std::vector<LocalPose> poses;
  uint64_t pose_index = 0, switch_index = 0;
  log::ReadOptions read_options;
  read_options.order = log::ReadOptions::Order::kLogTime;
  reader.ForEachMessage(
      [&](const log::MessageView& m) {
        const bool pose_message = std::find(pose_channels.begin(), pose_channels.end(),
                                            m.channel_id) != pose_channels.end();
        if (pose_message) {
          const MessageContext context(path, options.topic, ++pose_index, m.log_time);
          LocalPose p;
          p.index = pose_index;
          const log::std_msgs::Header* header = nullptr;
          const log::geometry_msgs::PoseWithCovariance* pose = nullptr;
          Odometry odometry;
          PoseWithCovarianceStamped stamped;
          if (is_odometry) {
            odometry = Decode<Odometry>(m, context);
            header = &odometry.header;
            pose = &odometry.pose;
            const auto& v = odometry.twist.twist.linear;
            p.v_body_m_s = Eigen::Vector3d(v.x, v.y, v.z);
            if (!p.v_body_m_s->allFinite()) {
              context.Fail("expected a finite twist, found a NaN or infinite value");
            }
          } else {
            stamped = Decode<PoseWithCovarianceStamped>(m, context);
            header = &stamped.header;
            pose = &stamped.pose;
          }
          p.stamp = log::FromRosTime(header->stamp);
          p.frame_id = std::string(header->frame_id.view());
          const auto& position = pose->pose.position;
          p.p_frame_body = Eigen::Vector3d(position.x, position.y, position.z);
          p.q_frame_body = context.CheckPose(p.p_frame_body, ToEigen(pose->pose.orientation));
          p.covariance = CovarianceOf(pose->covariance);
          if (p.covariance && !p.covariance->allFinite()) {
            context.Fail("expected a finite covariance, found a NaN or infinite entry");
          }
          poses.push_back(std::move(p));
        } else if (std::find(switch_channels.begin(), switch_channels.end(), m.channel_id) !=
                   switch_channels.end()) {
          const MessageContext context(path, options.frame_switch_topic, ++switch_index,
                                       m.log_time);
          const TransformStamped t = Decode<TransformStamped>(m, context);
          FrameSwitch s;
          s.stamp = log::FromRosTime(t.header.stamp);
          s.old_frame_id = std::string(t.header.frame_id.view());
          s.new_frame_id = std::string(t.child_frame_id.view());
          const Eigen::Vector3d translation(t.transform.translation.x, t.transform.translation.y,
                                            t.transform.translation.z);
          s.T_old_new.linear() =
              context.CheckPose(translation, ToEigen(t.transform.rotation)).toRotationMatrix();
          s.T_old_new.translation() = translation;
          result.switches.push_back(std::move(s));
        }
        return true;
      },
      read_options);
  for (const log::Damage& d : reader.damage()) {
    result.damage.push_back("offset " + std::to_string(d.offset) + ": " + d.what);
  }
  if (poses.empty()) {
    throw EvalError(path + ": expected pose messages on topic " + options.topic +
                    ", found none that could be read");
  }

  std::stable_sort(poses.begin(), poses.end(),
                   [](const LocalPose& a, const LocalPose& b) { return a.stamp < b.stamp; });
  std::stable_sort(result.switches.begin(), result.switches.end(),
                   [](const FrameSwitch& a, const FrameSwitch& b) { return a.stamp < b.stamp; });
  result.frame_id = poses.front().frame_id;
  const std::map<std::string, Eigen::Isometry3d> T_root_frame =
      options.frame_switch_topic.empty() ? std::map<std::string, Eigen::Isometry3d>{}
                                         : ChainFrames(result.frame_id, result.switches);

  Trajectory& trajectory = result.trajectory;
  trajectory.set_source(path);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const LocalPose& p = poses[i];
    if (i + 1 < poses.size() && poses[i + 1].stamp == p.stamp) {
      ++result.duplicate_stamps;  // Keep the later message of the same stamp.
      continue;
    }
    Eigen::Isometry3d T_root_local = Eigen::Isometry3d::Identity();
    if (!options.frame_switch_topic.empty()) {
      const auto it = T_root_frame.find(p.frame_id);
      if (it == T_root_frame.end()) {
        throw EvalError(
            path + ": message " + std::to_string(p.index) + " on " + options.topic + " (stamp " +
            FormatSeconds(p.stamp) + " s): expected a frame id connected to '" + result.frame_id +
            "' by the switches on " + options.frame_switch_topic + ", found '" + p.frame_id + "'");
      }
      T_root_local = it->second;
    }
    // Composed as quaternions so that poses in the first frame keep every bit.
    const Eigen::Quaterniond q_root_local(T_root_local.linear());
    PoseSample s;
    s.stamp = p.stamp;
    s.p_world_body = T_root_local * p.p_frame_body;
    s.q_world_body = UnitQuaternion(q_root_local * p.q_frame_body);
    if (p.v_body_m_s) s.v_world_body_m_s = s.q_world_body * *p.v_body_m_s;
    if (p.covariance) {
      Matrix6d J = Matrix6d::Identity();
      J.topLeftCorner<3, 3>() = T_root_local.linear();
      s.covariance = J * *p.covariance * J.transpose();
    }
    trajectory.Append(s);
  }
  return result;
}

}  // namespace rover::eval
