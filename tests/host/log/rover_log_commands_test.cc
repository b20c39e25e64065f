#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/log/mcap/mcap_reader.h"
#include "core/log/mcap/mcap_writer.h"
#include "core/log/msgs/all_msgs.h"
#include "host/log/commands.h"
#include "tests/support/temp_dir.h"

namespace rover::host {
namespace {

using ::testing::HasSubstr;
using ::testing::MatchesRegex;

std::span<const std::byte> AsBytes(std::string_view s) {
  return {reinterpret_cast<const std::byte*>(s.data()), s.size()};
}

// A log with 100 IMU messages over 1 s in chunks of ~10 messages.
void WriteImuLog(const std::string& path) {
  log::McapWriterOptions options;
  options.chunk_size_bytes = 3000;
  log::McapWriter writer(options);
  writer.Open(path);
  using Traits = log::MessageTraits<log::sensor_msgs::Imu>;
  const uint16_t schema =
      writer.AddSchema(Traits::kName, log::kRos2MsgSchemaEncoding, AsBytes(Traits::Definition()));
  const uint16_t channel = writer.AddChannel(schema, "/imu", log::kCdrMessageEncoding);
  for (int i = 0; i < 100; ++i) {
    log::sensor_msgs::Imu imu;
    imu.header.frame_id = "body";
    imu.header.stamp = {1, static_cast<uint32_t>(i * 10'000'000)};
    imu.angular_velocity.z = 0.25 * i;
    const auto bytes = log::SerializeMessage(imu);
    const uint64_t t = 1'000'000'000 + static_cast<uint64_t>(i) * 10'000'000;
    writer.WriteMessage(channel, static_cast<uint32_t>(i), t, t, bytes);
  }
  writer.Close();
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

class RoverLogCommandsTest : public ::testing::Test {
 protected:
  void SetUp() override { WriteImuLog(path_); }
  testing::TempDir dir_{"rover_log"};
  std::string path_ = dir_.File("imu.mcap").string();
  std::ostringstream out_, err_;
};

TEST_F(RoverLogCommandsTest, InfoListsChannelsCountsRatesAndRange) {
  EXPECT_EQ(RunInfo(path_, out_, err_), 0) << err_.str();
  const std::string text = out_.str();
  EXPECT_THAT(text, HasSubstr("summary:      intact"));
  EXPECT_THAT(text, HasSubstr("zstd"));
  EXPECT_THAT(text, HasSubstr("(0.990 s)"));
  EXPECT_THAT(text, HasSubstr("messages:     100 in 1 channels"));
  EXPECT_THAT(text, MatchesRegex("(.|\n)*/imu +sensor_msgs/msg/Imu +100 +100.00 (.|\n)*"));
}

TEST_F(RoverLogCommandsTest, ExportWritesOneRowPerMessageWithDecodedFields) {
  ExportOptions options{path_, "/imu", ""};
  EXPECT_EQ(RunExport(options, out_, err_), 0) << err_.str();
  const auto lines = Lines(out_.str());
  ASSERT_EQ(lines.size(), 101u);
  EXPECT_THAT(lines[0], HasSubstr("log_time_ns,sequence,header.stamp.sec,header.stamp.nanosec,"
                                  "header.frame_id,orientation.x"));
  // Column of angular_velocity.z, then check a row's value.
  std::vector<std::string> header;
  std::istringstream h(lines[0]);
  for (std::string c; std::getline(h, c, ',');) header.push_back(c);
  const auto col = std::find(header.begin(), header.end(), "angular_velocity.z") - header.begin();
  std::vector<std::string> row;
  std::istringstream r(lines[5]);
  for (std::string c; std::getline(r, c, ',');) row.push_back(c);
  ASSERT_EQ(row.size(), header.size());
  EXPECT_EQ(row[0], "1040000000");
  EXPECT_EQ(row[1], "4");
  EXPECT_EQ(row[static_cast<std::size_t>(col)], "1");
  EXPECT_THAT(err_.str(), HasSubstr("100 rows"));
}

TEST_F(RoverLogCommandsTest, ExportOfUnknownTopicListsTheTopics) {
  ExportOptions options{path_, "/nope", ""};
  EXPECT_EQ(RunExport(options, out_, err_), 2);
  EXPECT_THAT(err_.str(), HasSubstr("no topic '/nope'"));
  EXPECT_THAT(err_.str(), HasSubstr("/imu"));
}

TEST_F(RoverLogCommandsTest, VerifyPassesIntactAndReportsDamageWithOffset) {
  EXPECT_EQ(RunVerify(path_, out_, err_), 0);
  EXPECT_THAT(out_.str(), HasSubstr(": OK"));

  // Flip a byte in the middle of the second chunk.
  const log::McapReader reader = log::McapReader::Open(path_);
  ASSERT_GE(reader.chunks().size(), 3u);
  const log::ChunkInfo chunk = reader.chunks()[1];
  std::fstream f(path_, std::ios::in | std::ios::out | std::ios::binary);
  f.seekg(static_cast<std::streamoff>(chunk.offset + chunk.length / 2));
  char c = 0;
  f.get(c);
  f.seekp(static_cast<std::streamoff>(chunk.offset + chunk.length / 2));
  f.put(static_cast<char>(c ^ 0x5a));
  f.close();

  std::ostringstream out;
  EXPECT_EQ(RunVerify(path_, out, err_), 1);
  EXPECT_THAT(out.str(), HasSubstr("DAMAGED"));
  EXPECT_THAT(out.str(), HasSubstr(std::to_string(chunk.offset)));
}

TEST_F(RoverLogCommandsTest, RecoverSavesTheReadablePartOfATruncatedLog) {
  const auto size = std::filesystem::file_size(path_);
  std::filesystem::resize_file(path_, size * 2 / 3);  // power loss mid-write
  std::ostringstream verify_out;
  EXPECT_EQ(RunVerify(path_, verify_out, err_), 1);
  EXPECT_THAT(verify_out.str(), HasSubstr("truncated:         yes"));

  const std::string fixed = dir_.File("fixed.mcap").string();
  EXPECT_EQ(RunRecover(path_, fixed, {}, out_, err_), 0) << err_.str();
  EXPECT_THAT(out_.str(), HasSubstr("input was truncated"));
  const log::VerifyReport report = log::Verify(fixed);
  EXPECT_TRUE(report.ok);
  EXPECT_GT(report.message_count, 30u);
  EXPECT_LT(report.message_count, 100u);
  EXPECT_EQ(RunRecover(fixed, fixed, {}, out_, err_), 2);  // never overwrites its input
}

TEST(RoverLogInputTest, NonMcapFileIsAClearError) {
  const testing::TempDir dir("rover_log");
  const std::string path = dir.File("notes.txt").string();
  std::ofstream(path) << "not a flight log\n";
  std::ostringstream out, err;
  EXPECT_EQ(RunInfo(path, out, err), 2);
  EXPECT_THAT(err.str(), HasSubstr(path));
  EXPECT_EQ(RunVerify(path, out, err), 1);
}

}  // namespace
}  // namespace rover::host
