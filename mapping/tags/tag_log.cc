#include "mapping/tags/tag_log.h"

#include <cstdint>
#include <map>

#include "core/log/mcap/mcap_reader.h"
#include "core/log/msgs/message_traits.h"

namespace rover::mapping {

TagDetectionLog ReadTagDetections(const std::string& path) {
  TagDetectionLog out;
  log::McapReader reader = log::McapReader::Open(path);
  std::map<uint16_t, std::string> topic_of;
  reader.ForEachMessage([&](const log::MessageView& m) {
    // Channels first seen inside chunks (no summary) are only known now.
    if (topic_of.count(m.channel_id) == 0) {
      for (const auto& [id, channel] : reader.channels()) topic_of[id] = channel.topic;
    }
    if (topic_of[m.channel_id] != kTagDetectionTopic) return true;
    log::rover_msgs::TagDetection msg;
    std::string error;
    if (log::DeserializeMessage(m.data, &msg, &error)) {
      out.detections.push_back(std::move(msg));
    } else {
      out.problems.push_back(path + ": a tag detection cannot be decoded: " + error);
    }
    return true;
  });
  return out;
}

}  // namespace rover::mapping
