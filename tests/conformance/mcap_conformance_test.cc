// Independent conformance: logs written by the project's flight log are read
// by the reference JavaScript MCAP reader (@mcap/core) and decoded with
// @foxglove/rosmsg2-serialization from the schema text stored in the file.
// check_mcap.mjs compares channels, schemas, counts, timestamps and decoded
// fields against the expectations this test writes next to the log.

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include "core/log/flight/flight_log.h"
#include "core/log/msgs/all_msgs.h"
#include "tests/support/temp_dir.h"

namespace rover::log {
namespace {

namespace fs = std::filesystem;

std::string Json(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}
std::string Json(const std::string& s) { return "\"" + s + "\""; }  // test strings need no escapes

Time StampOf(int i) { return Time::FromNanoseconds(5'000'000'000 + int64_t{i} * 2'500'000); }

struct Expectations {
  std::ostringstream channels, samples;
  // `first`/`last` empty: the reader does not check the channel's time range.
  void Channel(const std::string& topic, std::string_view schema, int count,
               std::optional<Time> first, std::optional<Time> last) {
    channels << (channels.tellp() > 0 ? ",\n" : "") << "{\"topic\":" << Json(topic)
             << ",\"schema\":" << Json(std::string(schema))
             << ",\"schema_encoding\":\"ros2msg\",\"message_encoding\":\"cdr\",\"count\":" << count;
    if (first) channels << ",\"first_log_time_ns\":\"" << first->nanoseconds() << "\"";
    if (last) channels << ",\"last_log_time_ns\":\"" << last->nanoseconds() << "\"";
    channels << "}";
  }
  void Sample(const std::string& topic, int index, Time t,
              const std::vector<std::pair<std::string, std::string>>& fields) {
    samples << (samples.tellp() > 0 ? ",\n" : "") << "{\"topic\":" << Json(topic)
            << ",\"index\":" << index << ",\"log_time_ns\":\"" << t.nanoseconds()
            << "\",\"fields\":{";
    for (std::size_t i = 0; i < fields.size(); ++i) {
      samples << (i ? "," : "") << Json(fields[i].first) << ":" << fields[i].second;
    }
    samples << "}}";
  }
  void Write(const fs::path& path) const {
    std::ofstream(path) << "{\"profile\":\"ros2\",\n\"channels\":[" << channels.str()
                        << "],\n\"samples\":[" << samples.str() << "]}\n";
  }
};

sensor_msgs::Imu MakeImu(int i) {
  sensor_msgs::Imu m;
  m.header.stamp = ToRosTime(StampOf(i));
  m.header.frame_id = "body";
  m.orientation_covariance[0] = -1.0;
  m.angular_velocity = {0.01 * i, -0.02, 0.1 / (i + 1)};
  m.linear_acceleration = {0.3, -0.1 * i, 9.80665};
  m.angular_velocity_covariance[4] = 1.2e-5;
  return m;
}

// Writes a log with every standard message type through the real-time path
// and returns the expectations for the JavaScript reader.
Expectations WriteLog(const std::string& path, Compression compression) {
  FlightLogOptions options;
  options.mcap.compression = compression;
  options.mcap.chunk_size_bytes = 16 * 1024;        // many chunks, so indexes matter
  options.health_period = Duration::Seconds(3600);  // exactly one LogHealth, at Stop()
  FlightLog log(options);
  log.Open(path);
  auto* imu = log.AddChannel<sensor_msgs::Imu, 1024, 2048>("/imu");
  auto* odom = log.AddChannel<nav_msgs::Odometry>("/odom");
  auto* pose = log.AddChannel<geometry_msgs::PoseWithCovarianceStamped>("/pose");
  auto* tf = log.AddChannel<tf2_msgs::TFMessage>("/tf");
  auto* diag = log.AddChannel<diagnostic_msgs::DiagnosticArray, 4096, 16>("/diagnostics");
  auto* image = log.AddChannel<sensor_msgs::Image, 4096, 16>("/cam0/thumbnail");
  log.Start();

  Expectations e;
  constexpr int kImu = 1000;
  for (int i = 0; i < kImu; ++i) EXPECT_TRUE(imu->Log(StampOf(i), MakeImu(i)));
  e.Channel("/imu", MessageTraits<sensor_msgs::Imu>::kName, kImu, StampOf(0), StampOf(kImu - 1));
  for (int i : {0, 17, kImu - 1}) {
    const sensor_msgs::Imu m = MakeImu(i);
    e.Sample("/imu", i, StampOf(i),
             {{"header.frame_id", Json("body")},
              {"header.stamp.sec", std::to_string(m.header.stamp.sec)},
              {"header.stamp.nanosec", std::to_string(m.header.stamp.nanosec)},
              {"angular_velocity.x", Json(m.angular_velocity.x)},
              {"angular_velocity.z", Json(m.angular_velocity.z)},
              {"linear_acceleration.y", Json(m.linear_acceleration.y)},
              {"orientation_covariance.0", Json(-1.0)},
              {"angular_velocity_covariance.4", Json(1.2e-5)}});
  }

  nav_msgs::Odometry o;
  o.header.frame_id = "local/rover1/3";
  o.child_frame_id = "body";
  o.pose.pose.position = {1.5, -2.25, 0.125};
  o.pose.pose.orientation = {0.0, 0.0, 0.38268343236508978, 0.92387953251128674};
  o.pose.covariance[35] = 0.01;
  o.twist.twist.linear.x = 0.3;
  for (int i = 0; i < 10; ++i) EXPECT_TRUE(odom->Log(StampOf(4 * i), o));
  e.Channel("/odom", MessageTraits<nav_msgs::Odometry>::kName, 10, StampOf(0), StampOf(36));
  e.Sample("/odom", 3, StampOf(12),
           {{"header.frame_id", Json("local/rover1/3")},
            {"child_frame_id", Json("body")},
            {"pose.pose.position.y", Json(-2.25)},
            {"pose.pose.orientation.z", Json(o.pose.pose.orientation.z)},
            {"pose.covariance.35", Json(0.01)},
            {"twist.twist.linear.x", Json(0.3)}});

  geometry_msgs::PoseWithCovarianceStamped p;
  p.header.frame_id = "local/rover1/3";
  p.pose.pose.position.z = 42.0;
  p.pose.covariance[0] = 0.5;
  EXPECT_TRUE(pose->Log(StampOf(5), p));
  e.Channel("/pose", MessageTraits<geometry_msgs::PoseWithCovarianceStamped>::kName, 1, StampOf(5),
            StampOf(5));
  e.Sample("/pose", 0, StampOf(5),
           {{"pose.pose.position.z", Json(42.0)}, {"pose.covariance.0", Json(0.5)}});

  tf2_msgs::TFMessage t;
  t.transforms.resize(2);
  t.transforms[1].header.frame_id = "body";
  t.transforms[1].child_frame_id = "cam0";
  t.transforms[1].transform.translation = {0.1, 0.045, 0.2};
  t.transforms[1].transform.rotation = {-0.5, 0.5, -0.5, 0.5};
  EXPECT_TRUE(tf->Log(StampOf(6), t));
  e.Channel("/tf", MessageTraits<tf2_msgs::TFMessage>::kName, 1, StampOf(6), StampOf(6));
  e.Sample("/tf", 0, StampOf(6),
           {{"transforms.1.child_frame_id", Json("cam0")},
            {"transforms.1.transform.translation.y", Json(0.045)},
            {"transforms.1.transform.rotation.w", Json(0.5)}});

  diagnostic_msgs::DiagnosticArray d;
  d.status.resize(2);
  d.status[1].level = diagnostic_msgs::DiagnosticStatus::kWarn;
  d.status[1].name = "imu";
  d.status[1].hardware_id = "MTi-10";
  d.status[1].values = {{"rate_hz", "399.9"}, {"gaps", "1"}};
  EXPECT_TRUE(diag->Log(StampOf(7), d));
  e.Channel("/diagnostics", MessageTraits<diagnostic_msgs::DiagnosticArray>::kName, 1, StampOf(7),
            StampOf(7));
  e.Sample("/diagnostics", 0, StampOf(7),
           {{"status.1.level", "1"},
            {"status.1.name", Json("imu")},
            {"status.1.hardware_id", Json("MTi-10")},
            {"status.1.values.1.key", Json("gaps")},
            {"status.1.values.1.value", Json("1")}});

  sensor_msgs::Image img;
  img.header.frame_id = "cam0";
  img.height = 4;
  img.width = 6;
  img.encoding = "mono8";
  img.step = 6;
  for (int i = 0; i < 24; ++i) img.data.push_back(static_cast<uint8_t>(i * 10));
  EXPECT_TRUE(image->Log(StampOf(8), img));
  e.Channel("/cam0/thumbnail", MessageTraits<sensor_msgs::Image>::kName, 1, StampOf(8), StampOf(8));
  std::string pixels = "[";
  for (int i = 0; i < 24; ++i) pixels += (i ? "," : "") + std::to_string(i * 10);
  e.Sample("/cam0/thumbnail", 0, StampOf(8),
           {{"height", "4"}, {"width", "6"}, {"encoding", Json("mono8")}, {"data", pixels + "]"}});

  log.Stop();
  EXPECT_EQ(log.stats().dropped, 0u);
  EXPECT_TRUE(log.stats().error.empty()) << log.stats().error;
  return e;
}

class McapConformanceTest : public ::testing::TestWithParam<Compression> {};

TEST_P(McapConformanceTest, IndependentJavaScriptReaderAgrees) {
  const char* source_dir = std::getenv("ROVER_SOURCE_DIR");
  ASSERT_NE(source_dir, nullptr) << "ROVER_SOURCE_DIR not set (run through ctest)";
  const fs::path checker = fs::path(source_dir) / "tests/conformance";
  ASSERT_TRUE(fs::exists(checker / "node_modules/@mcap/core"))
      << "npm packages missing in " << checker << "; run scripts/install_deps.sh";

  const testing::TempDir dir("conformance");
  const std::string log_path = dir.File("log.mcap").string();
  Expectations e = WriteLog(log_path, GetParam());
  // One LogHealth, written at Stop() and stamped by the wall clock.
  e.Channel("/rover/log_health", MessageTraits<rover_msgs::LogHealth>::kName, 1, std::nullopt,
            std::nullopt);
  const fs::path expected = dir.File("expected.json");
  e.Write(expected);

  const std::string command = "node " + (checker / "check_mcap.mjs").string() + " " + log_path +
                              " " + expected.string() + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  char buf[512];
  while (fgets(buf, sizeof buf, pipe) != nullptr) output += buf;
  const int status = pclose(pipe);
  EXPECT_EQ(status, 0) << output;
  EXPECT_NE(output.find("OK "), std::string::npos) << output;
}

INSTANTIATE_TEST_SUITE_P(Compressions, McapConformanceTest,
                         ::testing::Values(Compression::kZstd, Compression::kLz4,
                                           Compression::kNone),
                         [](const auto& param_info) {
                           switch (param_info.param) {
                             case Compression::kZstd:
                               return std::string("zstd");
                             case Compression::kLz4:
                               return std::string("lz4");
                             case Compression::kNone:
                               return std::string("none");
                           }
                           return std::string("unknown");
                         });

}  // namespace
}  // namespace rover::log
