#include "tests/core/log/mcap/mcap_test_util.h"

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <random>
#include <stdexcept>

namespace rover::log::testing {

std::vector<std::byte> ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::vector<char> chars((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::byte> bytes(chars.size());
  for (size_t i = 0; i < chars.size(); ++i) bytes[i] = static_cast<std::byte>(chars[i]);
  return bytes;
}

void WriteFile(const std::string& path, const std::vector<std::byte>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
  if (!out) throw std::runtime_error("cannot write " + path);
}

std::ostream& operator<<(std::ostream& os, const TestMessage& m) {
  return os << "{channel " << m.channel_id << ", seq " << m.sequence << ", log " << m.log_time
            << ", pub " << m.publish_time << ", " << m.data.size() << " bytes}";
}

TestMessage ToTestMessage(const MessageView& view) {
  return TestMessage{view.channel_id, view.sequence, view.log_time, view.publish_time,
                     std::vector<std::byte>(view.data.begin(), view.data.end())};
}

TestLog WriteTestLog(const std::string& path, const McapWriterOptions& options,
                     size_t message_count, uint32_t seed, bool shuffle_times) {
  std::mt19937 rng(seed);
  TestLog log;
  McapWriter writer(options);
  writer.Open(path);

  const std::string imu_text = "builtin_interfaces/Time stamp\nfloat64[3] accel\n";
  const std::string pose_text = "float64 x\nfloat64 y\nfloat64 yaw\n";
  const auto as_bytes = [](const std::string& s) {
    return std::vector<std::byte>(reinterpret_cast<const std::byte*>(s.data()),
                                  reinterpret_cast<const std::byte*>(s.data()) + s.size());
  };
  log.schemas.push_back(Schema{0, "rover_msgs/msg/Imu", "ros2msg", as_bytes(imu_text)});
  log.schemas.push_back(Schema{0, "rover_msgs/msg/Pose", "ros2msg", as_bytes(pose_text)});
  for (Schema& s : log.schemas) s.id = writer.AddSchema(s.name, s.encoding, s.data);

  log.channels.push_back(Channel{0, log.schemas[0].id, "/imu", "cdr", {{"qos", "reliable"}}});
  log.channels.push_back(Channel{0, log.schemas[1].id, "/pose", "cdr", {}});
  log.channels.push_back(Channel{0, log.schemas[1].id, "/pose_ref", "cdr", {{"frame", "local"}}});
  for (Channel& c : log.channels) {
    c.id = writer.AddChannel(c.schema_id, c.topic, c.message_encoding, c.metadata);
  }
  const Metadata metadata{"rover", {{"board", "sim"}, {"serial", "0042"}}};
  writer.WriteMetadata(metadata.name, metadata.metadata);
  log.metadata.push_back(metadata);

  uint64_t t = 1'000'000'000;
  std::vector<uint32_t> sequences(log.channels.size(), 0);
  for (size_t i = 0; i < message_count; ++i) {
    const size_t c = rng() % log.channels.size();
    TestMessage m;
    m.channel_id = log.channels[c].id;
    m.sequence = sequences[c]++;
    t += 1'000'000 + rng() % 1'000'000;
    m.log_time = t;
    if (shuffle_times)
      m.log_time = t + (rng() % 50'000'000) - (c == 1 ? uint64_t{25'000'000} : uint64_t{0});
    m.publish_time = m.log_time - rng() % 1000;
    const size_t size = rng() % 400;
    m.data.resize(size);
    const bool compressible = rng() % 3 == 0;
    for (size_t k = 0; k < size; ++k) {
      m.data[k] = static_cast<std::byte>(compressible ? (k / 16) & 0xFFU : rng() & 0xFFU);
    }
    writer.WriteMessage(m.channel_id, m.sequence, m.log_time, m.publish_time, m.data);
    log.messages.push_back(std::move(m));
  }
  writer.Close();
  return log;
}

std::vector<TestMessage> ReadAll(McapReader& reader, const ReadOptions& options) {
  std::vector<TestMessage> out;
  reader.ForEachMessage(
      [&](const MessageView& view) {
        out.push_back(ToTestMessage(view));
        return true;
      },
      options);
  return out;
}

std::string Describe(const std::vector<Damage>& damage) {
  std::string out;
  for (const Damage& d : damage) out += "  @" + std::to_string(d.offset) + ": " + d.what + "\n";
  return out.empty() ? "  (none)\n" : out;
}

}  // namespace rover::log::testing
