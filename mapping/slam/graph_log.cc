#include "mapping/slam/graph_log.h"

#include <map>
#include <set>
#include <utility>

#include "core/log/mcap/mcap_reader.h"
#include "core/log/msgs/message_traits.h"

namespace rover::mapping {
namespace {

void ReadOne(const std::string& path, std::set<std::pair<int, uint64_t>>* seen,
             GraphLogContents* out) {
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
      } catch (const GraphError& e) {
        out->problems.push_back(path + ": " + e.what() + " (left out)");
      }
    } else if (topic == kSubmapOriginsTopic) {
      log::rover_msgs::SubmapOrigins msg;
      if (log::DeserializeMessage(m.data, &msg, &error)) out->last_origins = std::move(msg);
    } else if (topic == kGlobalPoseTopic) {
      log::geometry_msgs::PoseWithCovarianceStamped msg;
      if (log::DeserializeMessage(m.data, &msg, &error)) out->last_global_pose = msg;
    }
    return true;
  });
  for (const log::Damage& d : reader.damage()) {
    out->problems.push_back(path + ": at byte " + std::to_string(d.offset) + ": " + d.what);
  }
  out->truncated = out->truncated || reader.truncated();
}

}  // namespace

GraphLogContents ReadGraphLogs(const std::vector<std::string>& paths) {
  GraphLogContents out;
  std::set<std::pair<int, uint64_t>> seen;
  for (const std::string& path : paths) ReadOne(path, &seen, &out);
  return out;
}

}  // namespace rover::mapping
