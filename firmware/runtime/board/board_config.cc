#include "firmware/runtime/board/board_config.h"

#include <array>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace rover::runtime {
namespace {

/// (dotted key path from the document root, "expected ..., found ...").
using Problem = std::optional<std::pair<std::string, std::string>>;

std::string Number(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

/// lo < value <= hi (lo_open) or lo <= value <= hi; written so NaN fails.
Problem CheckRange(const std::string& key, double value, double lo, double hi, bool lo_open,
                   const std::string& what) {
  const bool above_lo = lo_open ? value > lo : value >= lo;
  if (above_lo && value <= hi) return std::nullopt;
  return std::make_pair(key, "expected " + what + " in " + (lo_open ? "(" : "[") + Number(lo) +
                                 ", " + Number(hi) + "], found " + Number(value));
}

bool IsNameChar(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
         c == '-';
}

/// The same folder, ignoring "." segments and trailing slashes.
bool SameFolder(const std::string& a, const std::string& b) {
  const auto normal = [](const std::string& p) {
    std::string s = std::filesystem::path(p).lexically_normal().string();
    while (s.size() > 1 && s.back() == '/') s.pop_back();
    return s;
  };
  return normal(a) == normal(b);
}

Problem ReplayProblem(BoardProfile profile, bool has_replay) {
  const bool wants_replay = profile == BoardProfile::kReplay;
  if (wants_replay && !has_replay) {
    return std::make_pair(std::string("replay"),
                          "expected a replay section (replay: {dataset: ...}) with board.profile "
                          "replay, found none");
  }
  if (!wants_replay && has_replay) {
    return std::make_pair(std::string("replay"), "expected no replay section with board.profile " +
                                                     std::string(BoardProfileName(profile)) +
                                                     ", found one");
  }
  return std::nullopt;
}

Problem HardwareProblem(BoardProfile profile, bool has_hardware) {
  const bool wants = profile == BoardProfile::kHardware;
  if (wants && !has_hardware) {
    return std::make_pair(std::string("hardware"),
                          "expected a hardware section (hardware: {calibration: ..., imu: ...}) "
                          "with board.profile hardware, found none");
  }
  if (!wants && has_hardware) {
    return std::make_pair(std::string("hardware"),
                          "expected no hardware section with board.profile " +
                              std::string(BoardProfileName(profile)) + ", found one");
  }
  return std::nullopt;
}

struct NamedThread {
  const char* key;
  const RtThreadOptions* options;
};

std::array<NamedThread, 6> Threads(const BoardThreadOptions& t) {
  return {{{"imu", &t.imu},
           {"camera", &t.camera},
           {"can", &t.can},
           {"vo", &t.vo},
           {"log", &t.log},
           {"service", &t.service}}};
}

Problem FindProblem(const BoardConfig& c) {
  // board
  const std::string& name = c.board.name;
  bool name_ok = !name.empty() && name.size() <= BoardIdentity::kMaxNameLength;
  for (const char ch : name) name_ok = name_ok && IsNameChar(ch);
  if (!name_ok) {
    return std::make_pair(std::string("board.name"),
                          "expected 1 to " + std::to_string(BoardIdentity::kMaxNameLength) +
                              " characters of [A-Za-z0-9_-], found \"" + name + "\"");
  }
  if (Problem p = ReplayProblem(c.board.profile, c.replay.has_value())) return p;
  if (Problem p = HardwareProblem(c.board.profile, c.hardware.has_value())) return p;
  if (c.hardware) {
    if (auto p = c.hardware->Problem()) return p;
  }
  if (c.replay && c.replay->dataset.empty()) {
    return std::make_pair(std::string("replay.dataset"),
                          "expected the folder of a EuRoC-layout dataset, found an empty path");
  }

  // threads
  const auto threads = Threads(c.threads);
  for (const NamedThread& t : threads) {
    if (auto p = t.options->Problem()) {
      return std::make_pair("threads." + std::string(t.key) + "." + p->first, p->second);
    }
  }
  for (std::size_t i = 0; i < threads.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (threads[i].options->name == threads[j].options->name) {
        return std::make_pair("threads." + std::string(threads[i].key) + ".name",
                              "expected a name no other thread has, found \"" +
                                  threads[i].options->name + "\" (also threads." + threads[j].key +
                                  ".name)");
      }
    }
  }
  const int imu_priority = c.threads.imu.priority;
  for (const NamedThread& t : threads) {
    if (t.options->priority > imu_priority) {
      return std::make_pair(
          "threads." + std::string(t.key) + ".priority",
          "expected at most threads.imu.priority (" + std::to_string(imu_priority) +
              "; nothing may preempt the IMU loop), found " + std::to_string(t.options->priority));
    }
  }

  // log
  if (c.log.folder.empty()) {
    return std::make_pair(std::string("log.folder"),
                          "expected the folder of the flight logs, found an empty path");
  }
  if (c.log.thumbnail_width_px < BoardLogOptions::kMinThumbnailWidthPx ||
      c.log.thumbnail_width_px > BoardLogOptions::kMaxThumbnailWidthPx) {
    return std::make_pair(std::string("log.thumbnail_width_px"),
                          "expected a width in [" +
                              std::to_string(BoardLogOptions::kMinThumbnailWidthPx) + ", " +
                              std::to_string(BoardLogOptions::kMaxThumbnailWidthPx) +
                              "] pixels, found " + std::to_string(c.log.thumbnail_width_px));
  }
  if (Problem p = CheckRange("log.thumbnail_rate_hz", c.log.thumbnail_rate_hz, 0.0,
                             BoardLogOptions::kMaxThumbnailRateHz, true, "a rate (Hz)")) {
    return p;
  }

  // log_service (its own values are checked by LogServiceOptions)
  if (c.log_service && !SameFolder(c.log_service->log_folder, c.log.folder)) {
    return std::make_pair(std::string("log_service.log_folder"),
                          "expected the folder roverd logs to (log.folder: " + c.log.folder +
                              "), found " + c.log_service->log_folder);
  }

  // ipc, health, mapd
  if (Problem p = CheckRange("ipc.roudi_wait_s", c.ipc.roudi_wait_s, 0.0,
                             BoardIpcOptions::kMaxRoudiWaitS, false, "a wait (s)")) {
    return p;
  }
  if (Problem p = CheckRange("health.period_s", c.health.period_s, HealthOptions::kMinPeriodS,
                             HealthOptions::kMaxPeriodS, false, "a period (s)")) {
    return p;
  }
  if (Problem p = CheckRange("health.stale_after_s", c.health.stale_after_s, 0.0,
                             HealthOptions::kMaxStaleAfterS, true, "a duration (s)")) {
    return p;
  }
  if (Problem p = CheckRange("health.rate_warn_fraction", c.health.rate_warn_fraction, 0.0, 1.0,
                             false, "a fraction")) {
    return p;
  }
  if (Problem p = CheckRange("mapd.submap_max_distance_m", c.mapd.submap_max_distance_m, 0.0,
                             BoardMapdOptions::kMaxSubmapDistanceM, true, "a distance (m)")) {
    return p;
  }
  if (Problem p =
          CheckRange("mapd.submap_max_position_sigma_m", c.mapd.submap_max_position_sigma_m, 0.0,
                     BoardMapdOptions::kMaxSubmapSigmaM, true, "a standard deviation (m)")) {
    return p;
  }
  if (Problem p = CheckRange("mapd.restart_backoff_s", c.mapd.restart_backoff_s, 0.0,
                             BoardMapdOptions::kMaxRestartBackoffS, false, "a backoff (s)")) {
    return p;
  }
  if (Problem p = CheckRange("mapd.mapping_rate_hz", c.mapd.mapping_rate_hz, 0.0,
                             BoardMapdOptions::kMaxMappingRateHz, false, "a rate (Hz)")) {
    return p;
  }
  for (const auto& [key, value] :
       {std::pair{"mapd.switch_along_sigma_per_m", c.mapd.switch_along_sigma_per_m},
        std::pair{"mapd.switch_across_sigma_per_m", c.mapd.switch_across_sigma_per_m},
        std::pair{"mapd.switch_yaw_sigma_rad_per_m", c.mapd.switch_yaw_sigma_rad_per_m}}) {
    if (Problem p = CheckRange(key, value, 0.0, 1.0, false, "an error per metre")) return p;
  }
  return std::nullopt;
}

/// Throws the ConfigError for `problem`, located at its key (or at the
/// deepest section present, naming the rest of the path, if the value is a
/// default).
[[noreturn]] void FailAt(const ConfigNode& root, const std::string& key_path,
                         const std::string& message) {
  ConfigNode node = root;
  std::string rest = key_path;
  for (std::size_t dot = rest.find('.'); dot != std::string::npos; dot = rest.find('.')) {
    const std::string section = rest.substr(0, dot);
    if (!node.Has(section)) node.Fail("", rest + " (default): " + message);
    node = node.Child(section);
    rest = rest.substr(dot + 1);
  }
  if (!node.Has(rest)) node.Fail("", rest + " (default): " + message);
  node.Fail(rest, message);
}

/// threads.<key>: RtThreadOptions::Load, but absent keys take `defaults`
/// (this thread's design values) rather than RtThreadOptions' own defaults.
RtThreadOptions LoadThread(const ConfigNode& threads, const std::string& key,
                           const RtThreadOptions& defaults) {
  if (!threads.Has(key)) return defaults;
  const ConfigNode node = threads.Child(key);
  RtThreadOptions o = RtThreadOptions::Load(node, defaults.name);
  if (!node.Has("priority")) o.priority = defaults.priority;
  if (!node.Has("nice")) o.nice = defaults.nice;
  if (!node.Has("cpus")) o.cpus = defaults.cpus;
  if (!node.Has("stack_prefault_bytes")) o.stack_prefault_bytes = defaults.stack_prefault_bytes;
  return o;
}

}  // namespace

std::string_view BoardProfileName(BoardProfile profile) {
  switch (profile) {
    case BoardProfile::kSim:
      return "sim";
    case BoardProfile::kReplay:
      return "replay";
    case BoardProfile::kHardware:
      return "hardware";
  }
  return "?";
}

std::string_view LogImagesName(LogImages images) {
  switch (images) {
    case LogImages::kNone:
      return "none";
    case LogImages::kThumbnails:
      return "thumbnails";
    case LogImages::kFull:
      return "full";
  }
  return "?";
}

RtSetupOptions BoardRealtimeOptions::ToRtSetupOptions(const std::string& program_name) const {
  RtSetupOptions o;
  o.program_name = program_name;
  o.lock_memory = lock_memory;
  return o;
}

BoardConfig BoardConfig::LoadFile(const std::string& path) {
  return Load(ConfigNode::LoadFile(path));
}

BoardConfig BoardConfig::Load(const ConfigNode& root) {
  BoardConfig c;

  const ConfigNode board = root.Child("board");
  c.board.name = board.Get<std::string>("name");
  c.board.profile = board.GetEnum<BoardProfile>("profile", {{"sim", BoardProfile::kSim},
                                                            {"replay", BoardProfile::kReplay},
                                                            {"hardware", BoardProfile::kHardware}});
  // Before reading the section, so a stray one is reported as such.
  if (Problem p = ReplayProblem(c.board.profile, root.Has("replay"))) {
    root.Fail(p->first, p->second);
  }
  if (Problem p = HardwareProblem(c.board.profile, root.Has("hardware"))) {
    root.Fail(p->first, p->second);
  }
  if (c.board.profile == BoardProfile::kHardware) {
    c.hardware = BoardHardwareOptions::Load(root.Child("hardware"));
  }
  if (c.board.profile == BoardProfile::kReplay) {
    const ConfigNode replay = root.Child("replay");
    c.replay = BoardReplayOptions{};
    c.replay->dataset = replay.Get<std::string>("dataset");
    c.replay->estimator_config = replay.Get<std::string>("estimator_config", "");
    c.replay->vo_config = replay.Get<std::string>("vo_config", "");
    c.replay->lockstep = replay.Get<bool>("lockstep", false);
  }

  if (root.Has("threads")) {
    const ConfigNode threads = root.Child("threads");
    const BoardThreadOptions d;
    c.threads.imu = LoadThread(threads, "imu", d.imu);
    c.threads.camera = LoadThread(threads, "camera", d.camera);
    c.threads.can = LoadThread(threads, "can", d.can);
    c.threads.vo = LoadThread(threads, "vo", d.vo);
    c.threads.log = LoadThread(threads, "log", d.log);
    c.threads.service = LoadThread(threads, "service", d.service);
  }

  if (root.Has("realtime")) {
    const ConfigNode realtime = root.Child("realtime");
    c.realtime.lock_memory = realtime.Get<bool>("lock_memory", c.realtime.lock_memory);
  }

  const ConfigNode log = root.Child("log");
  c.log.folder = log.Get<std::string>("folder");
  c.log.images = log.GetEnum<LogImages>("images",
                                        {{"none", LogImages::kNone},
                                         {"thumbnails", LogImages::kThumbnails},
                                         {"full", LogImages::kFull}},
                                        c.log.images);
  c.log.thumbnail_width_px = log.Get<int>("thumbnail_width_px", c.log.thumbnail_width_px);
  c.log.thumbnail_rate_hz = log.Get<double>("thumbnail_rate_hz", c.log.thumbnail_rate_hz);

  if (root.Has("log_service")) {
    c.log_service = LogServiceOptions::Load(root.Child("log_service"));
  }

  if (root.Has("ipc")) {
    const ConfigNode ipc = root.Child("ipc");
    c.ipc.roudi_wait_s = ipc.Get<double>("roudi_wait_s", c.ipc.roudi_wait_s);
  }

  if (root.Has("health")) {
    const ConfigNode health = root.Child("health");
    c.health.period_s = health.Get<double>("period_s", c.health.period_s);
    c.health.stale_after_s = health.Get<double>("stale_after_s", c.health.stale_after_s);
    c.health.rate_warn_fraction =
        health.Get<double>("rate_warn_fraction", c.health.rate_warn_fraction);
    c.health.watchdog = health.Get<bool>("watchdog", c.health.watchdog);
  }

  if (root.Has("mapd")) {
    const ConfigNode mapd = root.Child("mapd");
    c.mapd.submap_max_distance_m =
        mapd.Get<double>("submap_max_distance_m", c.mapd.submap_max_distance_m);
    c.mapd.submap_max_position_sigma_m =
        mapd.Get<double>("submap_max_position_sigma_m", c.mapd.submap_max_position_sigma_m);
    c.mapd.restart_backoff_s = mapd.Get<double>("restart_backoff_s", c.mapd.restart_backoff_s);
    c.mapd.mapping = mapd.Get<bool>("mapping", c.mapd.mapping);
    c.mapd.mapping_rate_hz = mapd.Get<double>("mapping_rate_hz", c.mapd.mapping_rate_hz);
    c.mapd.switch_along_sigma_per_m =
        mapd.Get<double>("switch_along_sigma_per_m", c.mapd.switch_along_sigma_per_m);
    c.mapd.switch_across_sigma_per_m =
        mapd.Get<double>("switch_across_sigma_per_m", c.mapd.switch_across_sigma_per_m);
    c.mapd.switch_yaw_sigma_rad_per_m =
        mapd.Get<double>("switch_yaw_sigma_rad_per_m", c.mapd.switch_yaw_sigma_rad_per_m);
    c.mapd.tags = mapd.Get<std::string>("tags", c.mapd.tags);
    c.mapd.tag_tables = mapd.Get<std::string>("tag_tables", c.mapd.tag_tables);
    c.mapd.build_missing_tag_tables =
        mapd.Get<bool>("build_missing_tag_tables", c.mapd.build_missing_tag_tables);
  }

  if (Problem p = FindProblem(c)) FailAt(root, p->first, p->second);
  root.CheckNoUnknownKeysRecursive();
  return c;
}

void BoardConfig::Validate() const {
  if (log_service) log_service->Validate();
  if (Problem p = FindProblem(*this)) throw std::invalid_argument(p->first + ": " + p->second);
}

std::string DefaultBoardConfigPath() { return "/etc/rover/board.yaml"; }

}  // namespace rover::runtime
