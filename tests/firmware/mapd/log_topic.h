#ifndef ROVER_TESTS_FIRMWARE_MAPD_LOG_TOPIC_H_
#define ROVER_TESTS_FIRMWARE_MAPD_LOG_TOPIC_H_

// Every message of one topic of an MCAP log, decoded, in log order.

#include <gtest/gtest.h>

#include <string>
#include <string_view>
#include <vector>

#include "core/log/mcap/mcap_reader.h"
#include "core/log/msgs/message_traits.h"

namespace rover::testing {

template <typename Msg>
std::vector<Msg> ReadTopic(const std::string& log_path, std::string_view topic) {
  log::McapReader reader = log::McapReader::Open(log_path);
  log::ReadOptions options;
  for (const auto& [id, channel] : reader.channels()) {
    if (channel.topic == topic) options.channel_ids.push_back(id);
  }
  std::vector<Msg> out;
  if (options.channel_ids.empty()) return out;  // an empty list would read every channel
  reader.ForEachMessage(
      [&](const log::MessageView& m) {
        Msg msg;
        EXPECT_TRUE(log::DeserializeMessage(m.data, &msg)) << topic;
        out.push_back(msg);
        return true;
      },
      options);
  return out;
}

}  // namespace rover::testing

#endif  // ROVER_TESTS_FIRMWARE_MAPD_LOG_TOPIC_H_
