#ifndef ROVER_FIRMWARE_RUNTIME_TOPICS_ROVER_TOPICS_H_
#define ROVER_FIRMWARE_RUNTIME_TOPICS_ROVER_TOPICS_H_

// What roverd and mapd say to each other over iceoryx (DESIGN.md):
//
//   /roverd/pose                  roverd -> mapd   every estimate (IMU rate)
//   /roverd/stereo_frame          roverd -> mapd   every captured stereo pair
//   /roverd/frame_switch          roverd -> mapd   every frame switch (graph factor w)
//   /mapd/frame_switch_request    mapd -> roverd   "start a new submap now"
//   /mapd/status                  mapd -> anyone   submaps, inputs, restarts
//   /roverd/diagnostics           roverd -> anyone health, once per health period
//   /mapd/global_pose             mapd -> anyone   the pose graph's global pose s_j (+) v_t
//   /mapd/submap_origins          mapd -> anyone   the optimised submap origins, in pages
//
// Messages are plain fixed-size structs (ipc::Message: copied byte-wise into
// shared memory), so both processes must be built from the same sources;
// kTopicsVersion is carried in every message so a stale binary on the other
// side is noticed instead of misread. Stamps are int64 nanoseconds on the
// sensors' clock (CLOCK_MONOTONIC on a board, simulated time in lockstep).

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

namespace rover::runtime::topics {

/// Bumped whenever a message below changes layout or meaning.
inline constexpr uint32_t kTopicsVersion = 5;

inline constexpr std::string_view kPoseTopic = "/roverd/pose";
inline constexpr std::string_view kStereoFrameTopic = "/roverd/stereo_frame";
inline constexpr std::string_view kFrameSwitchTopic = "/roverd/frame_switch";
inline constexpr std::string_view kFrameSwitchRequestTopic = "/mapd/frame_switch_request";
inline constexpr std::string_view kMapdStatusTopic = "/mapd/status";
inline constexpr std::string_view kDiagnosticsTopic = "/roverd/diagnostics";
inline constexpr std::string_view kStereoCalibrationTopic = "/roverd/stereo_calibration";
inline constexpr std::string_view kTraversabilityTopic = "/mapd/traversability";
inline constexpr std::string_view kGlobalPoseTopic = "/mapd/global_pose";
inline constexpr std::string_view kSubmapOriginsTopic = "/mapd/submap_origins";

/// PoseMsg::status bit: the filter is not initialised yet (the same bit as
/// estimator::kStatusNotInitialised, checked where roverd fills the message),
/// so readers need not link the estimator.
inline constexpr uint32_t kPoseStatusNotInitialised = 1u << 0;

/// One estimate of the local reference filter, in its current local frame.
struct PoseMsg {
  uint32_t version = kTopicsVersion;
  uint32_t frame_id = 0;  ///< local frame index; +1 per frame switch
  int64_t stamp_ns = 0;
  uint32_t status = 0;  ///< estimator::EskfStatusFlag bits
  uint32_t reserved = 0;
  std::array<double, 3> p_local_body_m{};
  std::array<double, 4> q_local_body_wxyz{1.0, 0.0, 0.0, 0.0};
  std::array<double, 3> v_local_m_s{};
  /// Row-major 6x6 covariance over [dp (m); dtheta (rad)] (graph factor v).
  std::array<double, 36> pose_covariance{};
  /// sqrt of the largest eigenvalue of the 3x3 position covariance: the
  /// submap trigger's "position sigma".
  double position_sigma_m = 0.0;
};

/// Largest image a StereoFrameMsg carries (mono8).
inline constexpr uint32_t kMaxFrameWidthPx = 1280;
inline constexpr uint32_t kMaxFrameHeightPx = 800;
inline constexpr uint32_t kMaxFramePixels = kMaxFrameWidthPx * kMaxFrameHeightPx;

/// A rectification-free stereo pair as captured (mono8, rows packed without
/// padding). About 2 MB: it lives in RouDi's 4 MiB pool and is written in
/// place (zero-copy) by the camera thread.
struct StereoFrameMsg {
  uint32_t version = kTopicsVersion;
  uint32_t width_px = 0;
  uint32_t height_px = 0;
  uint32_t reserved = 0;
  int64_t capture_stamp_ns = 0;
  uint64_t sequence = 0;  ///< the camera's frame counter
  // No initialisers: PublishInPlace default-initialises the message in shared
  // memory, and zeroing 2 MB per frame only to overwrite it would be waste.
  std::array<uint8_t, kMaxFramePixels> cam0;
  std::array<uint8_t, kMaxFramePixels> cam1;
};

/// A frame switch the filter made (graph factor w): the new local frame seen
/// from the old one, (p, yaw) with a row-major 4x4 covariance over
/// [dp (m, old frame); dyaw (rad)].
struct FrameSwitchMsg {
  uint32_t version = kTopicsVersion;
  uint32_t old_frame_id = 0;
  uint32_t new_frame_id = 0;
  uint32_t reserved = 0;
  int64_t stamp_ns = 0;
  std::array<double, 3> p_old_new_m{};
  double yaw_old_new_rad = 0.0;
  std::array<double, 16> covariance{};
};

/// Frame switches kept by the publisher for late subscribers (iceoryx caps
/// history at 16): a restarted mapd catches up on this many.
inline constexpr uint64_t kSwitchHistory = 16;

/// Why mapd asks for a new submap.
enum class SwitchReason : uint32_t {
  kDistance = 0,       ///< the distance driven in the submap exceeded its limit
  kPositionSigma = 1,  ///< the filter's position sigma exceeded its limit
  kRestart = 2,        ///< mapd (re)started: its earlier submap is gone
};

/// Returns "distance", "position_sigma" or "restart".
std::string_view ToString(SwitchReason reason);

/// mapd asks roverd for a frame switch (a new submap).
struct FrameSwitchRequestMsg {
  uint32_t version = kTopicsVersion;
  SwitchReason reason = SwitchReason::kDistance;
  uint64_t request_id = 0;  ///< counts up per mapd process, from 1
  /// The pose mapd decided on (its stamp and frame), for the record.
  int64_t pose_stamp_ns = 0;
  uint32_t pose_frame_id = 0;
  uint32_t reserved = 0;
};

/// mapd's state, published on every change and once a second.
struct MapdStatusMsg {
  uint32_t version = kTopicsVersion;
  int32_t pid = 0;
  uint32_t submaps = 0;  ///< submaps started by this process
  uint32_t current_frame_id = 0;
  uint64_t poses = 0;              ///< received
  uint64_t frames = 0;             ///< received
  uint64_t missed = 0;             ///< queue overflows noticed
  uint64_t requests = 0;           ///< frame switches requested
  double submap_distance_m = 0.0;  ///< driven in the current submap
  /// AprilTags decoded and what became of them (all zero with tags off).
  uint64_t tags_accepted = 0;        ///< into the graph (landmarks) or logged (robots)
  uint64_t tags_not_configured = 0;  ///< an id the marker list does not have
  uint64_t tags_refused = 0;         ///< by the detector's or the error model's checks, or no pose
  uint64_t tag_images_failed = 0;    ///< images the detector could not take
};

/// roverd's health report: a diagnostic_msgs/DiagnosticArray as ROS 2 CDR
/// (the bytes the flight log holds), so any subscriber decodes it with the
/// log's own message code (log::DeserializeMessage).
struct DiagnosticsMsg {
  static constexpr std::size_t kMaxCdrBytes = 32 * 1024;
  uint32_t version = kTopicsVersion;
  uint32_t cdr_size = 0;
  std::array<std::byte, kMaxCdrBytes> cdr;
};

/// mapd's robot-centred traversability grid: a nav_msgs/OccupancyGrid as
/// ROS 2 CDR (the bytes mapd's log holds); 0..100 per cell, 65 at the
/// step limit h_diff = h_max + Delta_d, -1 unknown. Published with history 1,
/// so a planner that connects gets the latest grid at once.
struct TraversabilityMsg {
  /// A 200 x 200 grid and its header, in RouDi's 64 KiB pool with the chunk header.
  static constexpr std::size_t kMaxCdrBytes = 60 * 1024;
  uint32_t version = kTopicsVersion;
  uint32_t cdr_size = 0;
  std::array<std::byte, kMaxCdrBytes> cdr;
};

/// The pose graph's current global pose of this rover after a graph update:
/// the optimised origin of the filter's current local frame composed with
/// the filter's latest estimate in it (s_j (+) v_t). Published with history
/// 1. It is never fed back into the filter.
struct GlobalPoseMsg {
  uint32_t version = kTopicsVersion;
  int32_t robot = 0;
  int64_t stamp_ns = 0;   ///< of the filter estimate it is composed from
  uint64_t update = 0;    ///< graph update it comes from (1, 2, ...)
  uint32_t frame_id = 0;  ///< the local frame of that estimate
  uint32_t reserved = 0;
  std::array<double, 3> p_world_body_m{};
  std::array<double, 4> q_world_body_wxyz{1.0, 0.0, 0.0, 0.0};
  /// Row-major 6x6 over [dp (world, m); dtheta (body, rad)].
  std::array<double, 36> covariance{};
};

/// One optimised submap origin (a local frame of the filter).
struct SubmapOriginEntry {
  int32_t robot = 0;
  uint32_t frame_id = 0;
  std::array<double, 3> p_world_origin_m{};
  std::array<double, 4> q_world_origin_wxyz{1.0, 0.0, 0.0, 0.0};
  /// Row-major 6x6 marginal over [dp (world, m); dtheta (origin, rad)];
  /// all zero when the graph did not compute it.
  std::array<double, 36> covariance{};
};

/// The origins after one graph update, in pages of at most kMaxOrigins
/// (one 64 KiB chunk each): page `page` of `pages` holds the origins
/// [first, first + count) of `total`, ordered by robot and frame. A reader
/// has the whole update once it holds every page with the same `update`.
/// Published with history 16 (iceoryx's cap), so a late subscriber gets the
/// latest update whole up to 16 pages (2048 origins).
struct SubmapOriginsMsg {
  static constexpr uint32_t kMaxOrigins = 128;
  uint32_t version = kTopicsVersion;
  uint32_t count = 0;
  uint64_t update = 0;
  int64_t stamp_ns = 0;  ///< of the newest factor in the update
  uint32_t first = 0;
  uint32_t total = 0;
  uint32_t page = 0;
  uint32_t pages = 0;
  std::array<SubmapOriginEntry, kMaxOrigins> origins{};
};

/// CameraCalibrationMsg::distortion_model values (calib::DistortionModel).
inline constexpr int32_t kDistortionRadialTangential = 0;  ///< k1, k2, p1, p2
inline constexpr int32_t kDistortionEquidistant = 1;       ///< k1, k2, k3, k4 (fisheye)

/// One camera's calibration as roverd uses it: pinhole with the lens model
/// `distortion_model`, and its pose on the body (the IMU).
struct CameraCalibrationMsg {
  int32_t width_px = 0;
  int32_t height_px = 0;
  int32_t distortion_model = kDistortionRadialTangential;
  int32_t reserved = 0;                ///< keeps the doubles 8-byte aligned
  std::array<double, 4> intrinsics{};  ///< fu, fv, cu, cv [px]
  std::array<double, 4> distortion{};  ///< coefficients of distortion_model
  std::array<double, 3> p_body_cam_m{};
  std::array<double, 4> q_body_cam_wxyz{1.0, 0.0, 0.0, 0.0};
  double vignetting_cos4_strength = 0.0;  ///< calib::CameraModel's
};

/// The stereo head's calibration, published once by roverd with history so
/// that a (re)started mapd receives it on connecting: mapd rectifies the
/// pairs of /roverd/stereo_frame with it.
struct StereoCalibrationMsg {
  uint32_t version = kTopicsVersion;
  uint32_t reserved = 0;
  CameraCalibrationMsg cam0;
  CameraCalibrationMsg cam1;
};

}  // namespace rover::runtime::topics

#endif  // ROVER_FIRMWARE_RUNTIME_TOPICS_ROVER_TOPICS_H_
