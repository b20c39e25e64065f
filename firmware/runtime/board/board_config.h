#ifndef ROVER_FIRMWARE_RUNTIME_BOARD_BOARD_CONFIG_H_
#define ROVER_FIRMWARE_RUNTIME_BOARD_BOARD_CONFIG_H_

// The board profile: one YAML file per board (firmware/config/*.yaml, the
// installed one is /etc/rover/board.yaml) that roverd and mapd both read.
//
//   board: {name: rover1, profile: replay}      # required; profile: sim | replay
//   replay: {dataset: /var/lib/rover/dataset}   # required with profile replay, else an error
//   threads:                                    # each an RtThreadOptions, all optional
//     imu: {priority: 80}                       # defaults: imu FIFO 80, camera FIFO 70,
//     camera: {priority: 70}                    # can FIFO 60, vo nice 10, log nice 0,
//     ...                                       # service nice 10
//   realtime: {lock_memory: true}
//   log:                                        # required (folder is)
//     folder: /var/lib/rover/logs
//     images: thumbnails                        # none | thumbnails | full
//     thumbnail_width_px: 188
//     thumbnail_rate_hz: 1.0
//   log_service: {...}                          # optional: LogServiceOptions; absent = off
//   ipc: {roudi_wait_s: 5.0}
//   health: {period_s: 1.0, stale_after_s: 1.0, rate_warn_fraction: 0.9, watchdog: true}
//   mapd: {submap_max_distance_m: 7.0, submap_max_position_sigma_m: 0.1,
//          restart_backoff_s: 1.0, mapping: true, mapping_rate_hz: 2.0,
//          switch_along_sigma_per_m: 0.0012, switch_across_sigma_per_m: 0.0006,
//          switch_yaw_sigma_rad_per_m: 2.0e-4, tags: /etc/rover/tags.yaml,
//          tag_tables: /etc/rover, build_missing_tag_tables: false}
//
// Every section except `board` and `log` is optional and every key in an
// optional section defaults to the value shown. Unknown keys are errors.
// Relative paths are relative to the working directory of the process (the
// repository root for `./rover run`), not to the config file.

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include "core/config/config.h"
#include "firmware/runtime/board/board_hardware_options.h"
#include "firmware/runtime/health/health_options.h"
#include "firmware/runtime/log_service/log_service_options.h"
#include "firmware/runtime/rt/rt_setup.h"
#include "firmware/runtime/rt/rt_thread_options.h"

namespace rover::runtime {

/// Which drivers roverd uses. To add one (e.g. real hardware): add the
/// enumerator, its name in BoardConfig::Load and BoardProfileName, and, if
/// it needs settings, a section named like the profile (as `replay`).
enum class BoardProfile {
  kSim,       ///< "sim": the simulator's drivers (roverd-sim).
  kReplay,    ///< "replay": a recorded EuRoC-layout dataset replayed as sensors.
  kHardware,  ///< "hardware": the board's real devices (section `hardware`).
};

/// "sim", "replay", "hardware": the name used in the YAML file.
std::string_view BoardProfileName(BoardProfile profile);

/// What the flight log keeps of the camera images.
enum class LogImages {
  kNone,        ///< "none": no images (VO results and clone requests only).
  kThumbnails,  ///< "thumbnails": downscaled cam0 images at thumbnail_rate_hz.
  kFull,        ///< "full": every frame of both cameras at full resolution.
};

/// "none", "thumbnails", "full".
std::string_view LogImagesName(LogImages images);

/// `board:` which board this is and which drivers it runs.
struct BoardIdentity {
  static constexpr std::size_t kMaxNameLength = 63;
  /// Robot name, also used in frame ids (local/<name>/<submap>): 1..63 of
  /// [A-Za-z0-9_-].
  std::string name;
  BoardProfile profile = BoardProfile::kSim;
};

/// `replay:` (profile replay only).
struct BoardReplayOptions {
  /// Folder of a EuRoC-layout dataset (holds mav0/).
  std::string dataset;
  /// EskfOptions YAML (e.g. host/eval/config/euroc_mav.yaml); empty: the
  /// defaults with the dataset's IMU noise figures.
  std::string estimator_config{};
  /// StereoOdometryOptions YAML; empty: the defaults at the dataset's rate.
  std::string vo_config{};
  /// Hand the data out as fast as the threads take it instead of at its
  /// recorded pace (bench and CI runs).
  bool lockstep = false;
};

/// `threads:` scheduling of every firmware thread (see DESIGN.md).
struct BoardThreadOptions {
  RtThreadOptions imu{"imu", 80, 0, {}, 64 * 1024};
  RtThreadOptions camera{"camera", 70, 0, {}, 64 * 1024};
  RtThreadOptions can{"can", 60, 0, {}, 64 * 1024};
  RtThreadOptions vo{"vo", 0, 10, {}, 64 * 1024};
  RtThreadOptions log{"log", 0, 0, {}, 64 * 1024};
  RtThreadOptions service{"service", 0, 10, {}, 64 * 1024};
};

/// `realtime:` process-wide real-time set-up (RtSetup).
struct BoardRealtimeOptions {
  /// mlockall(MCL_CURRENT | MCL_FUTURE) at start-up.
  bool lock_memory = true;

  /// The RtSetup options for a process named `program_name`.
  RtSetupOptions ToRtSetupOptions(const std::string& program_name) const;
};

/// `log:` the flight log.
struct BoardLogOptions {
  static constexpr int kMinThumbnailWidthPx = 16;
  static constexpr int kMaxThumbnailWidthPx = 4096;
  static constexpr double kMaxThumbnailRateHz = 100.0;

  /// Folder the MCAP flight logs are written to (required, non-empty).
  std::string folder;
  LogImages images = LogImages::kThumbnails;
  /// Width of a thumbnail (height keeps the aspect ratio); 188 = 752 / 4.
  int thumbnail_width_px = 188;
  /// Thumbnails per second, in (0, 100].
  double thumbnail_rate_hz = 1.0;
};

/// `ipc:` iceoryx.
struct BoardIpcOptions {
  static constexpr double kMaxRoudiWaitS = 600.0;
  /// How long a process waits for RouDi at start-up before giving up, s.
  double roudi_wait_s = 5.0;
};

/// `mapd:` the mapping process.
struct BoardMapdOptions {
  static constexpr double kMaxSubmapDistanceM = 1000.0;
  static constexpr double kMaxSubmapSigmaM = 100.0;
  static constexpr double kMaxRestartBackoffS = 600.0;
  /// Start a new submap after driving this far in the current one, m
  /// (thesis: 7 m).
  double submap_max_distance_m = 7.0;
  /// ... or when the filter's position standard deviation exceeds this, m
  /// (thesis: 0.1 m).
  double submap_max_position_sigma_m = 0.1;
  /// Wait before reconnecting / restarting after a failure, s.
  double restart_backoff_s = 1.0;
  /// Map the stereo pairs (depth, obstacles, submap voxels and clouds).
  bool mapping = true;
  /// At most this many pairs mapped per second of capture time (0: as many
  /// as mapd keeps up with).
  double mapping_rate_hz = 2.0;
  static constexpr double kMaxMappingRateHz = 1000.0;
  /// The odometry error the pose graph adds to each frame switch, per metre
  /// driven in the frame (mapping::FrameSwitchNoiseOptions): along the
  /// displacement and across it in m per m, yaw in rad per m. Measured
  /// against ground truth (`rover-sim map` reports the switches' NEES).
  double switch_along_sigma_per_m = 0.0012;
  double switch_across_sigma_per_m = 0.0006;
  double switch_yaw_sigma_rad_per_m = 2.0e-4;
  /// The AprilTag marker file (mapping::TagObserverOptions: family, sizes,
  /// which landmark or robot carries each id); empty: no tag detection.
  /// Relative paths as the log folder's.
  std::string tags{};
  /// Where the tag error tables are (rover-tags lut); empty: beside mapd's log.
  std::string tag_tables{};
  /// Build a missing table on the tag thread instead of switching detection
  /// off (the simulator; a board has its tables made ahead of time).
  bool build_missing_tag_tables = false;
};

/// The whole board profile.
struct BoardConfig {
  BoardIdentity board;
  /// Present iff board.profile is kReplay.
  std::optional<BoardReplayOptions> replay;
  /// Present iff board.profile is kHardware.
  std::optional<BoardHardwareOptions> hardware;
  BoardThreadOptions threads;
  BoardRealtimeOptions realtime;
  BoardLogOptions log;
  /// Absent: the HTTP log service is off.
  std::optional<LogServiceOptions> log_service;
  BoardIpcOptions ipc;
  /// `health:` the health thread and the systemd watchdog.
  HealthOptions health;
  BoardMapdOptions mapd;

  /// Reads and validates the YAML file at `path` (see Load). Throws
  /// ConfigError "path:line: key.path: expected ..., found ...".
  static BoardConfig LoadFile(const std::string& path);

  /// Reads every section from `root` (a whole document), validates the
  /// result (Validate's checks, located at the offending key) and rejects
  /// keys nobody read (root.CheckNoUnknownKeysRecursive()). Throws ConfigError.
  static BoardConfig Load(const ConfigNode& root);

  /// Throws std::invalid_argument "key.path: expected ..., found ..." for the
  /// first invalid value: any RtThreadOptions problem; thread names not
  /// unique; a thread with a higher SCHED_FIFO priority than the IMU thread;
  /// a bad board name; replay options present iff the profile is replay,
  /// with a non-empty dataset; an empty log folder or thumbnail settings out
  /// of range; log_service invalid or serving a folder other than
  /// log.folder; ipc, health and mapd values out of the ranges above (every
  /// duration and distance > 0, the backoff and RouDi wait >= 0).
  void Validate() const;
};

/// Where the installed board config lives: "/etc/rover/board.yaml".
std::string DefaultBoardConfigPath();

}  // namespace rover::runtime

#endif  // ROVER_FIRMWARE_RUNTIME_BOARD_BOARD_CONFIG_H_
