#include "firmware/runtime/board/board_config.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/config/config.h"
#include "tests/support/temp_dir.h"

namespace rover::runtime {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::StartsWith;

// The smallest valid profile: every other key takes its default.
constexpr const char* kMinimal = "board: {name: r1, profile: sim}\nlog: {folder: /tmp/logs}\n";

BoardConfig LoadYaml(const std::string& yaml) {
  return BoardConfig::Load(ConfigNode::LoadString(yaml, "board.yaml"));
}

// The ConfigError text of loading `yaml` ("" if it loads).
std::string LoadError(const std::string& yaml) {
  try {
    LoadYaml(yaml);
    return "";
  } catch (const ConfigError& e) {
    return e.what();
  }
}

// The std::invalid_argument text of c.Validate() ("" if valid).
std::string ValidateError(const BoardConfig& c) {
  try {
    c.Validate();
    return "";
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
}

std::filesystem::path ConfigDir() { return std::filesystem::path(ROVER_BOARD_CONFIG_DIR); }

TEST(BoardConfigTest, EveryShippedProfileLoadsAndValidates) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(ConfigDir())) {
    if (entry.path().extension() != ".yaml") continue;
    names.push_back(entry.path().filename().string());
    SCOPED_TRACE(entry.path().string());
    try {
      const BoardConfig c = BoardConfig::LoadFile(entry.path().string());
      EXPECT_NO_THROW(c.Validate());
    } catch (const std::exception& e) {
      ADD_FAILURE() << e.what();
    }
  }
  std::sort(names.begin(), names.end());
  EXPECT_THAT(names, ::testing::IsSupersetOf({"board.yaml", "sim.yaml"}));
}

TEST(BoardConfigTest, InstalledDefaultProfileIsTheBoardYaml) {
  EXPECT_EQ(DefaultBoardConfigPath(), "/etc/rover/board.yaml");
  const BoardConfig c = BoardConfig::LoadFile((ConfigDir() / "board.yaml").string());
  EXPECT_EQ(c.board.profile, BoardProfile::kReplay);
  ASSERT_TRUE(c.replay.has_value());
  EXPECT_FALSE(c.replay->dataset.empty());
  EXPECT_EQ(c.log.folder, "/var/lib/rover/logs");
  ASSERT_TRUE(c.log_service.has_value());
  EXPECT_EQ(c.log_service->bind_address, "0.0.0.0");
  EXPECT_EQ(c.log_service->port, 8086);
  EXPECT_EQ(c.log_service->token_file, "/etc/rover/log_service.token");
  EXPECT_TRUE(c.log_service->token.empty());
  EXPECT_TRUE(c.realtime.lock_memory);
  EXPECT_TRUE(c.health.watchdog);
}

TEST(BoardConfigTest, SimProfileLogsToBuildMissionWithoutService) {
  const BoardConfig c = BoardConfig::LoadFile((ConfigDir() / "sim.yaml").string());
  EXPECT_EQ(c.board.profile, BoardProfile::kSim);
  EXPECT_FALSE(c.replay.has_value());
  EXPECT_EQ(c.log.folder, "build/mission");
  EXPECT_FALSE(c.log_service.has_value());
  EXPECT_FALSE(c.realtime.lock_memory);
  EXPECT_FALSE(c.health.watchdog);
}

TEST(BoardConfigTest, MinimalProfileTakesTheDesignDefaults) {
  const BoardConfig c = LoadYaml(kMinimal);
  EXPECT_EQ(c.board.name, "r1");
  EXPECT_EQ(c.board.profile, BoardProfile::kSim);
  EXPECT_FALSE(c.replay.has_value());

  EXPECT_EQ(c.threads.imu.name, "imu");
  EXPECT_EQ(c.threads.imu.priority, 80);
  EXPECT_EQ(c.threads.camera.priority, 70);
  EXPECT_EQ(c.threads.can.priority, 60);
  EXPECT_EQ(c.threads.vo.priority, 0);
  EXPECT_EQ(c.threads.vo.nice, 10);
  EXPECT_EQ(c.threads.log.priority, 0);
  EXPECT_EQ(c.threads.log.nice, 0);
  EXPECT_EQ(c.threads.service.priority, 0);
  EXPECT_EQ(c.threads.service.nice, 10);

  EXPECT_TRUE(c.realtime.lock_memory);
  EXPECT_EQ(c.log.folder, "/tmp/logs");
  EXPECT_EQ(c.log.images, LogImages::kThumbnails);
  EXPECT_EQ(c.log.thumbnail_width_px, 188);
  EXPECT_EQ(c.log.thumbnail_rate_hz, 1.0);
  EXPECT_FALSE(c.log_service.has_value());
  EXPECT_EQ(c.ipc.roudi_wait_s, 5.0);
  EXPECT_EQ(c.health.period_s, 1.0);
  EXPECT_EQ(c.health.stale_after_s, 1.0);
  EXPECT_EQ(c.health.rate_warn_fraction, 0.9);
  EXPECT_TRUE(c.health.watchdog);
  EXPECT_EQ(c.mapd.submap_max_distance_m, 7.0);
  EXPECT_EQ(c.mapd.submap_max_position_sigma_m, 0.1);
  EXPECT_EQ(c.mapd.restart_backoff_s, 1.0);
  EXPECT_NO_THROW(c.Validate());

  // A default-constructed config differs only in what the YAML must supply.
  BoardConfig d;
  d.board.name = "r1";
  d.log.folder = "/tmp/logs";
  EXPECT_NO_THROW(d.Validate());
}

TEST(BoardConfigTest, ReadsEveryKey) {
  const BoardConfig c = LoadYaml(
      "board: {name: rover-2_b, profile: replay}\n"
      "replay: {dataset: /data/loop100}\n"
      "threads:\n"
      "  imu: {name: imu_loop, priority: 90, nice: -5, cpus: [0], stack_prefault_bytes: 131072}\n"
      "  camera: {priority: 75}\n"
      "  can: {priority: 1}\n"
      "  vo: {nice: 19}\n"
      "  log: {nice: 5}\n"
      "  service: {name: http}\n"
      "realtime: {lock_memory: false}\n"
      "log: {folder: /logs, images: full, thumbnail_width_px: 320, thumbnail_rate_hz: 2.5}\n"
      "log_service: {bind_address: 0.0.0.0, port: 9000, log_folder: /logs/, token: abc}\n"
      "ipc: {roudi_wait_s: 0.5}\n"
      "health: {period_s: 0.5, stale_after_s: 2.0, rate_warn_fraction: 0, watchdog: false}\n"
      "mapd: {submap_max_distance_m: 10.0, submap_max_position_sigma_m: 0.2,"
      " restart_backoff_s: 3.0, switch_along_sigma_per_m: 0.004,"
      " switch_across_sigma_per_m: 0.002, switch_yaw_sigma_rad_per_m: 0.001,"
      " tags: /etc/rover/tags.yaml, tag_tables: /etc/rover/tables, build_missing_tag_tables: "
      "true}\n");
  EXPECT_EQ(c.board.name, "rover-2_b");
  EXPECT_EQ(c.board.profile, BoardProfile::kReplay);
  ASSERT_TRUE(c.replay.has_value());
  EXPECT_EQ(c.replay->dataset, "/data/loop100");
  EXPECT_EQ(c.threads.imu.name, "imu_loop");
  EXPECT_EQ(c.threads.imu.priority, 90);
  EXPECT_EQ(c.threads.imu.nice, -5);
  EXPECT_EQ(c.threads.imu.cpus, std::vector<int>{0});
  EXPECT_EQ(c.threads.imu.stack_prefault_bytes, 131072u);
  EXPECT_EQ(c.threads.camera.priority, 75);
  EXPECT_EQ(c.threads.can.priority, 1);
  EXPECT_EQ(c.threads.vo.nice, 19);
  EXPECT_EQ(c.threads.log.nice, 5);
  EXPECT_EQ(c.threads.service.name, "http");
  EXPECT_FALSE(c.realtime.lock_memory);
  EXPECT_EQ(c.log.images, LogImages::kFull);
  EXPECT_EQ(c.log.thumbnail_width_px, 320);
  EXPECT_EQ(c.log.thumbnail_rate_hz, 2.5);
  ASSERT_TRUE(c.log_service.has_value());
  EXPECT_EQ(c.log_service->port, 9000);
  EXPECT_EQ(c.log_service->token, "abc");
  EXPECT_EQ(c.ipc.roudi_wait_s, 0.5);
  EXPECT_EQ(c.health.period_s, 0.5);
  EXPECT_EQ(c.health.stale_after_s, 2.0);
  EXPECT_EQ(c.health.rate_warn_fraction, 0.0);
  EXPECT_FALSE(c.health.watchdog);
  EXPECT_EQ(c.mapd.submap_max_distance_m, 10.0);
  EXPECT_EQ(c.mapd.submap_max_position_sigma_m, 0.2);
  EXPECT_EQ(c.mapd.restart_backoff_s, 3.0);
  EXPECT_EQ(c.mapd.switch_along_sigma_per_m, 0.004);
  EXPECT_EQ(c.mapd.switch_across_sigma_per_m, 0.002);
  EXPECT_EQ(c.mapd.switch_yaw_sigma_rad_per_m, 0.001);
  EXPECT_EQ(c.mapd.tags, "/etc/rover/tags.yaml");
  EXPECT_EQ(c.mapd.tag_tables, "/etc/rover/tables");
  EXPECT_TRUE(c.mapd.build_missing_tag_tables);
}

TEST(BoardConfigTest, PartialThreadSectionKeepsThatThreadsDefaults) {
  const BoardConfig c =
      LoadYaml(std::string(kMinimal) + "threads:\n  imu: {nice: -5}\n  vo: {priority: 0}\n");
  EXPECT_EQ(c.threads.imu.name, "imu");
  EXPECT_EQ(c.threads.imu.priority, 80);  // not RtThreadOptions' own 0
  EXPECT_EQ(c.threads.imu.nice, -5);
  EXPECT_EQ(c.threads.vo.nice, 10);
  EXPECT_EQ(c.threads.camera.priority, 70);
}

TEST(BoardConfigTest, UnknownKeyIsRejectedWithItsName) {
  EXPECT_THAT(LoadError(std::string(kMinimal) + "health: {period_s: 1.0, watchdgo: true}\n"),
              AllOf(StartsWith("board.yaml:3: health.watchdgo: unknown key"),
                    HasSubstr("did you mean \"watchdog\"")));
  EXPECT_THAT(LoadError(std::string(kMinimal) + "mapdd: {}\n"),
              HasSubstr("board.yaml:3: mapdd: unknown key"));
  EXPECT_THAT(LoadError(std::string(kMinimal) + "threads: {gpu: {priority: 10}}\n"),
              HasSubstr("threads.gpu: unknown key"));
}

TEST(BoardConfigTest, PriorityOutOfRangeIsRejected) {
  EXPECT_THAT(LoadError(std::string(kMinimal) + "threads:\n  imu: {priority: 120}\n"),
              AllOf(StartsWith("board.yaml:4: threads.imu.priority: "), HasSubstr("expected"),
                    HasSubstr("found 120")));
  EXPECT_THAT(LoadError(std::string(kMinimal) + "threads:\n  vo: {nice: 25}\n"),
              AllOf(StartsWith("board.yaml:4: threads.vo.nice: "), HasSubstr("found 25")));
}

TEST(BoardConfigTest, NoThreadMayOutrankTheImuLoop) {
  EXPECT_THAT(LoadError(std::string(kMinimal) + "threads:\n  camera: {priority: 90}\n"),
              AllOf(StartsWith("board.yaml:4: threads.camera.priority: "),
                    HasSubstr("expected at most threads.imu.priority (80"), HasSubstr("found 90")));
  // The camera's default (70) outranks a lowered IMU thread: reported at the
  // threads section, naming the defaulted key.
  EXPECT_THAT(LoadError(std::string(kMinimal) + "threads:\n  imu: {priority: 50}\n"),
              AllOf(StartsWith("board.yaml:3: threads: camera.priority (default): "),
                    HasSubstr("found 70")));
  // Everything at SCHED_OTHER (a workstation) is fine.
  EXPECT_EQ(
      LoadError(std::string(kMinimal) + "threads:\n  imu: {priority: 0}\n  camera: {priority: 0}\n"
                                        "  can: {priority: 0}\n"),
      "");
}

TEST(BoardConfigTest, ThreadNamesMustBeUnique) {
  EXPECT_THAT(LoadError(std::string(kMinimal) + "threads:\n  log: {name: imu}\n"),
              AllOf(StartsWith("board.yaml:4: threads.log.name: "),
                    HasSubstr("found \"imu\" (also threads.imu.name)")));
}

TEST(BoardConfigTest, LogFolderIsRequired) {
  EXPECT_THAT(LoadError("board: {name: r1, profile: sim}\nlog: {images: none}\n"),
              HasSubstr("log.folder: missing required key"));
  EXPECT_THAT(LoadError("board: {name: r1, profile: sim}\n"),
              HasSubstr("log: missing required key"));
  EXPECT_THAT(LoadError("board: {name: r1, profile: sim}\nlog: {folder: \"\"}\n"),
              AllOf(StartsWith("board.yaml:2: log.folder: "),
                    HasSubstr("expected the folder of the flight logs, found an empty path")));
}

TEST(BoardConfigTest, BoardSectionIsRequiredAndChecked) {
  EXPECT_THAT(LoadError("log: {folder: /tmp}\n"), HasSubstr("board: missing required key"));
  EXPECT_THAT(LoadError("board: {name: r1, profile: real}\nlog: {folder: /tmp}\n"),
              AllOf(HasSubstr("board.profile"), HasSubstr("sim"), HasSubstr("replay"),
                    HasSubstr("hardware"), HasSubstr("real")));
  EXPECT_THAT(LoadError("board: {name: rover 1, profile: sim}\nlog: {folder: /tmp}\n"),
              AllOf(StartsWith("board.yaml:1: board.name: "), HasSubstr("found \"rover 1\"")));
}

TEST(BoardConfigTest, ReplaySectionGoesWithTheReplayProfile) {
  EXPECT_THAT(LoadError("board: {name: r1, profile: replay}\nlog: {folder: /tmp}\n"),
              AllOf(HasSubstr("replay: expected a replay section"), HasSubstr("found none")));
  EXPECT_THAT(LoadError(std::string(kMinimal) + "replay: {dataset: /data}\n"),
              AllOf(StartsWith("board.yaml:3: replay: "),
                    HasSubstr("expected no replay section with board.profile sim")));
  EXPECT_THAT(LoadError("board: {name: r1, profile: replay}\nreplay: {}\nlog: {folder: /tmp}\n"),
              HasSubstr("replay.dataset: missing required key"));
  EXPECT_THAT(
      LoadError("board: {name: r1, profile: replay}\nreplay: {dataset: ''}\nlog: {folder: /t}\n"),
      HasSubstr("replay.dataset: expected the folder of a EuRoC-layout dataset"));
}

constexpr char kHardware[] =
    "board: {name: r1, profile: hardware}\n"
    "log: {folder: /tmp}\n"
    "hardware:\n"
    "  calibration: /etc/rover/calibration\n"
    "  imu: {driver: xsens, device: /dev/ttyUSB0, rate_hz: 400, baud_rate: 921600}\n"
    "  camera:\n"
    "    driver: aravis\n"
    "    cam0: 192.168.10.11\n"
    "    cam1: 192.168.10.12\n"
    "    width_px: 1024\n"
    "    height_px: 508\n"
    "    rate_hz: 15\n"
    "    trigger: {chip: gpiochip2, line: 5}\n"
    "  can: {interface: can1}\n";

TEST(BoardConfigTest, HardwareSectionNamesTheDevices) {
  const BoardConfig c = LoadYaml(kHardware);
  EXPECT_EQ(c.board.profile, BoardProfile::kHardware);
  ASSERT_TRUE(c.hardware.has_value());
  EXPECT_FALSE(c.replay.has_value());
  const BoardHardwareOptions& h = *c.hardware;
  EXPECT_EQ(h.calibration, "/etc/rover/calibration");
  EXPECT_EQ(h.imu.driver, ImuDriverKind::kXsens);
  EXPECT_EQ(h.imu.device, "/dev/ttyUSB0");
  EXPECT_EQ(h.imu.baud_rate, 921600);
  ASSERT_TRUE(h.camera.has_value());
  EXPECT_EQ(h.camera->driver, CameraDriverKind::kAravis);
  EXPECT_EQ(h.camera->pixel_format, "Mono8");  // Aravis's default format
  EXPECT_EQ(h.camera->width_px, 1024);
  EXPECT_EQ(h.camera->rate_hz, 15.0);
  ASSERT_TRUE(h.camera->trigger.has_value());
  EXPECT_EQ(h.camera->trigger->chip, "gpiochip2");
  EXPECT_EQ(h.camera->trigger->line, 5);
  EXPECT_EQ(h.camera->trigger->pulse_width_s, 0.001);
  ASSERT_TRUE(h.can.has_value());
  EXPECT_EQ(h.can->interface, "can1");
  EXPECT_NO_THROW(c.Validate());
}

TEST(BoardConfigTest, HardwareSectionGoesWithTheHardwareProfileAndIsChecked) {
  EXPECT_THAT(LoadError("board: {name: r1, profile: hardware}\nlog: {folder: /tmp}\n"),
              HasSubstr("hardware: expected a hardware section"));
  EXPECT_THAT(LoadError(std::string(kMinimal) +
                        "hardware: {calibration: /c, imu: {driver: xsens, device: /dev/ttyS1}}\n"),
              HasSubstr("expected no hardware section with board.profile sim"));
  auto with = [](const std::string& from, const std::string& to) {
    std::string yaml = kHardware;
    const std::size_t at = yaml.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return yaml.replace(at, from.size(), to);
  };
  EXPECT_THAT(LoadError(with("driver: xsens", "driver: mpu6050")),
              AllOf(HasSubstr("hardware.imu.driver"), HasSubstr("adis16448")));
  EXPECT_THAT(LoadError(with("cam1: 192.168.10.12", "cam1: 192.168.10.11")),
              AllOf(HasSubstr("hardware.camera.cam0"), HasSubstr("two different cameras")));
  EXPECT_THAT(LoadError(with("rate_hz: 15", "rate_hz: 500")),
              AllOf(HasSubstr("hardware.camera.rate_hz"), HasSubstr("[1, 100]")));
  EXPECT_THAT(LoadError(with("line: 5}", "line: 5, pulse_width_s: 0.5}")),
              HasSubstr("hardware.camera.trigger.pulse_width_s"));
  EXPECT_THAT(LoadError(with("interface: can1", "interface: ''")),
              HasSubstr("hardware.can.interface"));
  EXPECT_THAT(
      LoadError(with("  can: {interface: can1}\n", "  can: {interface: can1, bitrate: 1}\n")),
      HasSubstr("bitrate"));
}

TEST(BoardConfigTest, LogServiceIsValidatedAndServesTheLogFolder) {
  EXPECT_THAT(LoadError(std::string(kMinimal) + "log_service: {log_folder: /tmp/logs}\n"),
              AllOf(HasSubstr("log_service"), HasSubstr("exactly one of token and token_file")));
  EXPECT_THAT(LoadError(std::string(kMinimal) +
                        "log_service: {log_folder: /var/other, token_file: /etc/t}\n"),
              AllOf(StartsWith("board.yaml:3: log_service.log_folder: "),
                    HasSubstr("expected the folder roverd logs to (log.folder: /tmp/logs)"),
                    HasSubstr("found /var/other")));
  EXPECT_EQ(LoadError(std::string(kMinimal) +
                      "log_service: {log_folder: /tmp/./logs/, token_file: /etc/t}\n"),
            "");
}

TEST(BoardConfigTest, ValuesOutOfRangeNameTheirKey) {
  struct Case {
    std::string yaml;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {"log: {folder: /l, thumbnail_width_px: 5}\n",
       "log.thumbnail_width_px: expected a width in [16, 4096] pixels, found 5"},
      {"log: {folder: /l, thumbnail_rate_hz: 0}\n",
       "log.thumbnail_rate_hz: expected a rate (Hz) in (0, 100], found 0"},
      {"log: {folder: /l, images: some}\n", "log.images: "},
      {"log: {folder: /l}\nipc: {roudi_wait_s: -1}\n",
       "ipc.roudi_wait_s: expected a wait (s) in [0, 600], found -1"},
      {"log: {folder: /l}\nhealth: {period_s: 0}\n",
       "health.period_s: expected a period (s) in [0.01, 60], found 0"},
      {"log: {folder: /l}\nhealth: {stale_after_s: 0}\n",
       "health.stale_after_s: expected a duration (s) in (0, 60], found 0"},
      {"log: {folder: /l}\nhealth: {rate_warn_fraction: 1.5}\n",
       "health.rate_warn_fraction: expected a fraction in [0, 1], found 1.5"},
      {"log: {folder: /l}\nhealth: {watchdog: 1}\n", "health.watchdog: "},
      {"log: {folder: /l}\nmapd: {submap_max_distance_m: 0}\n",
       "mapd.submap_max_distance_m: expected a distance (m) in (0, 1000], found 0"},
      {"log: {folder: /l}\nmapd: {submap_max_position_sigma_m: -0.1}\n",
       "mapd.submap_max_position_sigma_m: expected a standard deviation (m) in (0, 100], found "
       "-0.1"},
      {"log: {folder: /l}\nmapd: {restart_backoff_s: 1000}\n",
       "mapd.restart_backoff_s: expected a backoff (s) in [0, 600], found 1000"},
      {"log: {folder: /l}\nmapd: {switch_along_sigma_per_m: -0.001}\n",
       "mapd.switch_along_sigma_per_m: expected an error per metre in [0, 1], found -0.001"},
      {"log: {folder: /l}\nrealtime: {lock_memory: yes please}\n", "realtime.lock_memory: "},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.yaml);
    EXPECT_THAT(LoadError("board: {name: r1, profile: sim}\n" + c.yaml),
                AllOf(StartsWith("board.yaml:"), HasSubstr(c.expected)));
  }
}

TEST(BoardConfigTest, FileErrorsNameTheFileAndLine) {
  const testing::TempDir dir;
  const std::string path = dir.File("board.yaml").string();
  {
    std::ofstream out(path);
    out << "board:\n  name: r1\n  profile: sim\nlog:\n  folder: /l\nhealth:\n  period_s: 100\n";
  }
  try {
    BoardConfig::LoadFile(path);
    ADD_FAILURE() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_THAT(e.what(), StartsWith(path + ":7: health.period_s: expected"));
  }
  EXPECT_THROW(BoardConfig::LoadFile(dir.File("missing.yaml").string()), ConfigError);
}

TEST(BoardConfigTest, ValidateChecksConfigsBuiltInCode) {
  BoardConfig c;
  c.board.name = "r1";
  EXPECT_EQ(ValidateError(c),
            "log.folder: expected the folder of the flight logs, found an empty path");
  c.log.folder = "/logs";
  EXPECT_EQ(ValidateError(c), "");

  BoardConfig bad = c;
  bad.threads.can.priority = 100;
  EXPECT_THAT(ValidateError(bad), StartsWith("threads.can.priority: expected"));
  bad = c;
  bad.board.profile = BoardProfile::kReplay;
  EXPECT_THAT(ValidateError(bad), StartsWith("replay: expected a replay section"));
  bad.replay = BoardReplayOptions{"/data"};
  EXPECT_EQ(ValidateError(bad), "");
  bad = c;
  bad.log_service = LogServiceOptions{};
  bad.log_service->log_folder = "/logs";
  EXPECT_THAT(ValidateError(bad), HasSubstr("exactly one of token and token_file"));
  bad.log_service->token = "t";
  EXPECT_EQ(ValidateError(bad), "");
  bad = c;
  bad.mapd.submap_max_position_sigma_m = 0.0;
  EXPECT_THAT(ValidateError(bad), StartsWith("mapd.submap_max_position_sigma_m: expected"));
}

TEST(BoardConfigTest, NamesAndRtSetupOptions) {
  EXPECT_EQ(BoardProfileName(BoardProfile::kSim), "sim");
  EXPECT_EQ(BoardProfileName(BoardProfile::kReplay), "replay");
  EXPECT_EQ(LogImagesName(LogImages::kNone), "none");
  EXPECT_EQ(LogImagesName(LogImages::kThumbnails), "thumbnails");
  EXPECT_EQ(LogImagesName(LogImages::kFull), "full");
  BoardRealtimeOptions realtime;
  realtime.lock_memory = false;
  const RtSetupOptions o = realtime.ToRtSetupOptions("mapd");
  EXPECT_EQ(o.program_name, "mapd");
  EXPECT_FALSE(o.lock_memory);
}

}  // namespace
}  // namespace rover::runtime
