#include "mapping/slam/graph_log.h"

#include <algorithm>
#include <cstdint>
#include <map>
#include <set>
#include <tuple>
#include <utility>

#include "core/log/mcap/mcap_reader.h"
#include "core/log/msgs/message_traits.h"
#include "mapping/graph/rover_graph.h"

namespace rover::mapping {
namespace {

// Keeps a team message once by (origin, stream, seq).
using TeamMessageKey = std::tuple<int32_t, uint8_t, uint64_t>;

void ReadOne(const std::string& path, std::set<std::pair<int, uint64_t>>* seen,
             std::set<TeamMessageKey>* seen_team, GraphLogContents* out) {
  log::McapReader reader = log::McapReader::Open(path);
  std::map<uint16_t, std::string> topic_of;
  for (const auto& [id, channel] : reader.channels()) topic_of[id] = channel.topic;
  reader.ForEachMessage([&](const log::MessageView& m) {
    // Channels first seen inside chunks (no summary) are only known now.
    if (topic_of.count(m.channel_id) == 0) {
      for (const auto& [id, channel] : reader.channels()) topic_of[id] = channel.topic;
    }
    const std::string& topic = topic_of[m.channel_id];
    std::string error;
    if (topic == kGraphFactorTopic) {
      log::rover_msgs::GraphFactor msg;
      if (!log::DeserializeMessage(m.data, &msg, &error)) {
        out->problems.push_back(path + ": a graph factor cannot be decoded: " + error);
        return true;
      }
      try {
        GraphFactorRecord record = FromMsg(msg);
        if (!seen->insert({record.a.robot, record.id}).second) {
          ++out->duplicates;
          return true;
        }
        out->factors.push_back(std::move(record));
        out->messages.push_back(std::move(msg));
      } catch (const GraphError& e) {
        out->problems.push_back(path + ": " + e.what() + " (left out)");
      }
    } else if (topic == kSubmapOriginsTopic) {
      log::rover_msgs::SubmapOrigins msg;
      if (log::DeserializeMessage(m.data, &msg, &error)) {
        if (!msg.origins.empty()) out->robot_of_log[path] = msg.origins.front().robot;
        out->last_origins = std::move(msg);
      }
    } else if (topic == kGlobalPoseTopic) {
      log::geometry_msgs::PoseWithCovarianceStamped msg;
      if (log::DeserializeMessage(m.data, &msg, &error)) out->last_global_pose = msg;
    } else if (topic == kTeamSentTopic || topic == kTeamReceivedTopic) {
      log::rover_msgs::TeamMessage msg;
      if (!log::DeserializeMessage(m.data, &msg, &error)) {
        out->problems.push_back(path + ": a team message cannot be decoded: " + error);
        return true;
      }
      if (seen_team->insert({msg.origin, msg.stream, msg.seq}).second) {
        (topic == kTeamSentTopic ? out->team_sent : out->team_received).push_back(std::move(msg));
      }
    }
    return true;
  });
  for (const log::Damage& d : reader.damage()) {
    out->problems.push_back(path + ": at byte " + std::to_string(d.offset) + ": " + d.what);
  }
  out->truncated = out->truncated || reader.truncated();
}

}  // namespace

log::geometry_msgs::Pose ToPoseMsg(const Eigen::Isometry3d& T) {
  log::geometry_msgs::Pose m;
  const Eigen::Quaterniond q(T.linear());
  m.position = {T.translation().x(), T.translation().y(), T.translation().z()};
  m.orientation = {q.x(), q.y(), q.z(), q.w()};
  return m;
}

Eigen::Isometry3d FromPoseMsg(const log::geometry_msgs::Pose& m) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() =
      Eigen::Quaterniond(m.orientation.w, m.orientation.x, m.orientation.y, m.orientation.z)
          .normalized()
          .toRotationMatrix();
  T.translation() = Eigen::Vector3d(m.position.x, m.position.y, m.position.z);
  return T;
}

Matrix6d RosPoseCovariance(const Eigen::Matrix3d& R_world_body, const Matrix6d& covariance) {
  // R Exp(dphi) = Exp(R dphi) R: the world-axis rotation error is R dphi.
  Matrix6d J = Matrix6d::Identity();
  J.bottomRightCorner<3, 3>() = R_world_body;
  return J * covariance * J.transpose();
}

Eigen::Isometry3d MovedFinalGlobalPose(const GraphLogContents& logged, const RoverGraph& graph) {
  const log::rover_msgs::SubmapOrigin& newest = logged.last_origins->origins.back();
  const Eigen::Isometry3d T_local_body =
      FromPoseMsg(newest.pose).inverse() * FromPoseMsg(logged.last_global_pose->pose.pose);
  return graph.Origin(newest.robot, newest.submap) * T_local_body;
}

std::optional<Eigen::Isometry3d> GraphInMap(const log::rover_msgs::SubmapOrigins& graph,
                                            const std::map<uint32_t, Eigen::Isometry3d>& origins) {
  if (graph.origins.empty()) return std::nullopt;
  const auto anchor =
      std::min_element(graph.origins.begin(), graph.origins.end(),
                       [](const auto& a, const auto& b) { return a.submap < b.submap; });
  if (anchor->submap < 0 || anchor->submap > UINT32_MAX) return std::nullopt;
  const auto chained = origins.find(static_cast<uint32_t>(anchor->submap));
  if (chained == origins.end()) return std::nullopt;
  return Eigen::Isometry3d(chained->second * FromPoseMsg(anchor->pose).inverse());
}

std::size_t PlaceAtGraphOrigins(const log::rover_msgs::SubmapOrigins& graph,
                                std::map<uint32_t, Eigen::Isometry3d>* origins) {
  const std::optional<Eigen::Isometry3d> T_map_graph = GraphInMap(graph, *origins);
  if (!T_map_graph) return 0;
  std::size_t placed = 0;
  for (const auto& o : graph.origins) {
    if (o.submap < 0 || o.submap > UINT32_MAX) continue;
    (*origins)[static_cast<uint32_t>(o.submap)] = *T_map_graph * FromPoseMsg(o.pose);
    ++placed;
  }
  return placed;
}

GraphLogContents ReadGraphLogs(const std::vector<std::string>& paths) {
  GraphLogContents out;
  std::set<std::pair<int, uint64_t>> seen;
  std::set<TeamMessageKey> seen_team;
  for (const std::string& path : paths) ReadOne(path, &seen, &seen_team, &out);
  return out;
}

}  // namespace rover::mapping
