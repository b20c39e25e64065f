#include "firmware/mapd/mapd.h"

#include <malloc.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>

#include <opencv2/core.hpp>

#include "core/log/msgs/message_traits.h"
#include "core/stats/percentile.h"
#include "firmware/mapd/submap_archive.h"
#include "mapping/slam/graph_factor_record.h"
#include "mapping/slam/graph_log.h"
#include "mapping/submap/submap_messages.h"
#include "mapping/tags/tag_log.h"

namespace rover::mapd {
namespace {

namespace topics = runtime::topics;

ipc::Topic TopicOf(std::string_view name) {
  std::string error;
  std::optional<ipc::Topic> topic = ipc::Topic::Parse(name, &error);
  if (!topic) throw std::runtime_error("mapd: bad topic " + std::string(name) + ": " + error);
  return *topic;
}

template <typename T>
std::unique_ptr<ipc::Subscriber<T>> Subscribe(ipc::Transport* transport, std::string_view name,
                                              uint64_t queue, uint64_t history = 0) {
  std::string error;
  auto s = transport->MakeSubscriber<T>(
      TopicOf(name), {.queue_capacity = queue, .history_request = history}, &error);
  if (s == nullptr) {
    throw std::runtime_error("mapd: cannot subscribe to " + std::string(name) + ": " + error);
  }
  return s;
}

// A percentile for the summary; 0 before there is any sample.
double PercentileOrZero(const std::vector<double>& samples, double percent) {
  return samples.empty() ? 0.0 : stats::Percentile(samples, percent);
}

void FillPose(const Eigen::Isometry3d& T, std::array<double, 3>* p, std::array<double, 4>* q_wxyz) {
  const Eigen::Quaterniond q(T.linear());
  *p = {T.translation().x(), T.translation().y(), T.translation().z()};
  *q_wxyz = {q.w(), q.x(), q.y(), q.z()};
}

void FillCovariance(const mapping::Matrix6d& c, std::array<double, 36>* out) {
  for (int i = 0; i < 36; ++i) (*out)[static_cast<std::size_t>(i)] = c(i / 6, i % 6);
}

template <typename T>
std::unique_ptr<ipc::Publisher<T>> Advertise(ipc::Transport* transport, std::string_view name,
                                             uint64_t history) {
  std::string error;
  auto p = transport->MakePublisher<T>(TopicOf(name), {.history_capacity = history}, &error);
  if (p == nullptr) {
    throw std::runtime_error("mapd: cannot publish " + std::string(name) + ": " + error);
  }
  return p;
}

// Throws std::invalid_argument for a distortion model this build does not
// know; TakeCalibration reports it and does not map.
calib::CameraModel CameraOf(const topics::CameraCalibrationMsg& m) {
  calib::CameraModel c;
  c.width_px = m.width_px;
  c.height_px = m.height_px;
  if (m.distortion_model == topics::kDistortionRadialTangential) {
    c.distortion_model = calib::DistortionModel::kRadialTangential;
  } else if (m.distortion_model == topics::kDistortionEquidistant) {
    c.distortion_model = calib::DistortionModel::kEquidistant;
  } else {
    throw std::invalid_argument(
        "expected distortion_model " + std::to_string(topics::kDistortionRadialTangential) +
        " (radial-tangential) or " + std::to_string(topics::kDistortionEquidistant) +
        " (equidistant), found " + std::to_string(m.distortion_model));
  }
  c.intrinsics = m.intrinsics;
  c.distortion = m.distortion;
  const Eigen::Quaterniond q(m.q_body_cam_wxyz[0], m.q_body_cam_wxyz[1], m.q_body_cam_wxyz[2],
                             m.q_body_cam_wxyz[3]);
  c.T_body_cam.linear() = q.normalized().toRotationMatrix();
  c.T_body_cam.translation() =
      Eigen::Vector3d(m.p_body_cam_m[0], m.p_body_cam_m[1], m.p_body_cam_m[2]);
  c.vignetting_cos4_strength = m.vignetting_cos4_strength;
  return c;
}

StampedPose PoseOf(const topics::PoseMsg& m) {
  StampedPose p;
  p.stamp = Time::FromNanoseconds(m.stamp_ns);
  p.frame_id = m.frame_id;
  const auto& q = m.q_local_body_wxyz;
  p.T_local_body.linear() = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).toRotationMatrix();
  p.T_local_body.translation() =
      Eigen::Vector3d(m.p_local_body_m[0], m.p_local_body_m[1], m.p_local_body_m[2]);
  for (int i = 0; i < 36; ++i) {
    p.covariance(i / 6, i % 6) = m.pose_covariance[static_cast<std::size_t>(i)];
  }
  return p;
}

// The newest earlier mapd log beside `own_stem`.mcap: a restarted mapd's
// predecessor. Names sort by start time ("mapd-<UTC time>-<pid>").
std::optional<std::string> PreviousMapdLog(const std::string& own_stem) {
  namespace fs = std::filesystem;
  const fs::path own(own_stem + ".mcap");
  std::optional<fs::path> best;
  std::error_code error;
  const fs::path folder = own.has_parent_path() ? own.parent_path() : fs::path(".");
  for (const auto& entry : fs::directory_iterator(folder, error)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("mapd-", 0) != 0 || entry.path().extension() != ".mcap" ||
        entry.path().filename() == own.filename()) {
      continue;
    }
    if (!best || name > best->filename().string()) best = entry.path();
  }
  if (!best) return std::nullopt;
  return best->string();
}

}  // namespace

void MapdOptions::Validate() const {
  if (!(max_mapping_rate_hz >= 0.0) || !std::isfinite(max_mapping_rate_hz)) {
    throw std::invalid_argument("MapdOptions.max_mapping_rate_hz: expected >= 0, got " +
                                std::to_string(max_mapping_rate_hz));
  }
  if (pose_history < 2) {
    throw std::invalid_argument("MapdOptions.pose_history: expected >= 2 estimates, got " +
                                std::to_string(pose_history));
  }
  if (!(traversability_period > Duration::Zero())) {
    throw std::invalid_argument("MapdOptions.traversability_period: expected > 0 s");
  }
  local_mapper.Validate();
  if (tags) {
    if (!mapping)
      throw std::invalid_argument("MapdOptions.tags: needs mapping (the rectified images)");
    tags->Validate();
    tag_ambiguity.Validate();
  }
  switch_noise.Validate();
  submap.Validate();
  loop.Validate();
  if (team) {
    if (!slam) throw std::invalid_argument("MapdOptions.team: needs slam (the pose graph)");
    team->Validate();
  }
}

Mapd::Mapd(const MapdOptions& options, ipc::Transport* transport,
           std::unique_ptr<link::LinkEndpoint> team_link)
    : options_((options.Validate(), options)),
      trigger_(options.trigger),
      poses_(Subscribe<topics::PoseMsg>(transport, topics::kPoseTopic, options.pose_queue)),
      // Two frames: a slow mapd works on the newest pair, never on a backlog.
      frames_(Subscribe<topics::StereoFrameMsg>(transport, topics::kStereoFrameTopic, 2)),
      // The switches roverd kept: a restarted mapd needs the ones it missed.
      switches_(Subscribe<topics::FrameSwitchMsg>(transport, topics::kFrameSwitchTopic,
                                                  topics::kSwitchHistory, topics::kSwitchHistory)),
      requests_(
          Advertise<topics::FrameSwitchRequestMsg>(transport, topics::kFrameSwitchRequestTopic, 0)),
      // History 1: whoever connects later sees mapd's state at once.
      status_(Advertise<topics::MapdStatusMsg>(transport, topics::kMapdStatusTopic, 1)),
      frame_buffer_(std::make_unique<topics::StereoFrameMsg>()),
      history_(options.pose_history),
      team_history_(options.team ? options.team_pose_history : 1),
      tag_resolver_(options.tag_ambiguity),
      team_link_(std::move(team_link)) {
  if (options_.team && !team_link_) {
    throw std::invalid_argument("MapdOptions.team: given, but no team link");
  }
  if (options_.mapping) {
    std::string error;
    // History 1: roverd published the calibration once, maybe long ago.
    calibration_ = transport->MakeSubscriber<topics::StereoCalibrationMsg>(
        TopicOf(topics::kStereoCalibrationTopic), {.queue_capacity = 1, .history_request = 1},
        &error);
    if (calibration_ == nullptr) {
      throw std::runtime_error("mapd: cannot subscribe to " +
                               std::string(topics::kStereoCalibrationTopic) + ": " + error);
    }
    pending_frame_ = std::make_unique<topics::StereoFrameMsg>();
    traversability_ =
        Advertise<topics::TraversabilityMsg>(transport, topics::kTraversabilityTopic, 1);
    archive_ = std::make_unique<SubmapArchive>(options_.output_stem, options_.robot_name,
                                               mapping::MapComposerOptions{});
  }
  if (options_.slam) {
    // History: a late subscriber gets the latest pose, and the latest
    // origins whole up to 16 pages.
    global_pose_ = Advertise<topics::GlobalPoseMsg>(transport, topics::kGlobalPoseTopic, 1);
    origins_ = Advertise<topics::SubmapOriginsMsg>(transport, topics::kSubmapOriginsTopic,
                                                   topics::kSwitchHistory);
    slam_ = std::make_unique<SlamWorker>(options_.graph, options_.robot_id);
    LoadResumeCandidate();
    if (options_.mapping && options_.loop_closures) {
      LoopCloserOptions loop = options_.loop;
      // Spilled match data go beside mapd's log (the board's log partition,
      // not a RAM-backed /tmp) unless the configuration names a directory.
      if (loop.store.spill_directory.empty() && !options_.output_stem.empty()) {
        loop.store.spill_directory =
            std::filesystem::path(options_.output_stem).parent_path().string();
      }
      loop_ = std::make_unique<LoopCloser>(loop, options_.robot_id);
    }
  }
  trigger_.RequestAtNextPose();
}

Mapd::~Mapd() {
  try {
    Shutdown();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mapd: shutting down: %s\n", e.what());
  }
}

int Mapd::Poll() {
  int handled = 0;
  // Switches first: a switch queued before an estimate of the new frame
  // must be known when that estimate opens the new submap.
  topics::FrameSwitchMsg record;
  while (switches_->TryTake(&record)) {
    OnFrameSwitch(record);
    ++handled;
  }
  topics::PoseMsg pose;
  while (poses_->TryTake(&pose)) {
    OnPose(pose);
    ++handled;
  }
  if (calibration_ && !mapper_) TakeCalibration();
  TryMapPending();
  while (frames_->TryTake(frame_buffer_.get())) {
    OnFrame(*frame_buffer_);
    ++handled;
  }
  TryMapPending();
  if (loop_) TakeLoopMatches();
  if (tags_) TakeTagResults();
  if (team_) {
    TakeTeam();
    if (!waiting_detections_.empty()) RetryWaitingDetections(false);
  }
  if (slam_) TakeSlamSnapshot();
  if (poses_->HasMissedData()) ++stats_.missed;
  if (frames_->HasMissedData()) ++stats_.missed;
  const Time now = Time::Now();
  if (handled > 0 && now - last_status_wall_ >= options_.status_period) PublishStatus();
  return handled;
}

void Mapd::OnFrameSwitch(const topics::FrameSwitchMsg& record) {
  if (record.version != topics::kTopicsVersion) {
    ++stats_.version_mismatches;
    return;
  }
  ++stats_.frame_switches;
  if (slam_) DecideResume(&record);
  if (slam_ && switched_frames_.count(record.old_frame_id) == 0) {
    switched_frames_.insert(record.old_frame_id);
    EnsurePrior(record.old_frame_id, record.stamp_ns);
    Eigen::Matrix4d covariance;
    for (int i = 0; i < 16; ++i)
      covariance(i / 4, i % 4) = record.covariance[static_cast<std::size_t>(i)];
    const Eigen::Vector3d p_old_new_m(record.p_old_new_m[0], record.p_old_new_m[1],
                                      record.p_old_new_m[2]);
    mapping::GraphFactorRecord w = mapping::FrameSwitchFactor(
        options_.robot_id, record.old_frame_id, p_old_new_m, record.yaw_old_new_rad,
        mapping::FrameSwitchCovariance(covariance, p_old_new_m, options_.switch_noise));
    w.stamp_ns = record.stamp_ns;
    if (record.new_frame_id == record.old_frame_id + 1) {
      AddFactor(std::move(w));
    } else {
      std::fprintf(stderr, "mapd: frame switch %u -> %u skips frames: left out of the graph\n",
                   record.old_frame_id, record.new_frame_id);
    }
  }
  // Topics are not ordered against each other: the new frame's first
  // estimates may have arrived (and opened its submap) before this record.
  if (!submaps_.empty() && submaps_.back().frame_id == record.new_frame_id &&
      !submaps_.back().origin) {
    submaps_.back().origin = record;
    return;
  }
  pending_origin_ = record;
}

SubmapRecord* Mapd::Current(uint32_t frame_id, Time stamp) {
  if (!submaps_.empty() && submaps_.back().frame_id == frame_id) return &submaps_.back();
  const bool matches_origin = pending_origin_ && pending_origin_->new_frame_id == frame_id;
  const bool answers_request = last_reason_ && request_frame_ != frame_id;
  // Only frames this process saw begin are its submaps: the mission's first
  // frame, or one that answers a request or comes with its switch record. A
  // frame joined half-way (after a restart) is not.
  if (frame_id != 0 && !matches_origin && !answers_request) return nullptr;
  SubmapRecord s;
  s.index = static_cast<uint32_t>(submaps_.size());
  s.frame_id = frame_id;
  if (matches_origin) {
    s.origin = pending_origin_;
    pending_origin_.reset();
  }
  if (answers_request) {
    s.reason = last_reason_;
    last_reason_.reset();
  }
  s.first_stamp = stamp;
  // The previous frame is over: archive its map now rather than when the
  // next pair arrives.
  FinishMappingSubmap();
  submaps_.push_back(s);
  if (archive_) archive_->OpenFrame(submaps_.back());
  PublishStatus();
  return &submaps_.back();
}

void Mapd::OnPose(const topics::PoseMsg& pose) {
  if (pose.version != topics::kTopicsVersion) {
    ++stats_.version_mismatches;
    return;
  }
  ++stats_.poses;
  newest_stamp_ns_ = std::max(newest_stamp_ns_, pose.stamp_ns);
  history_.Add(PoseOf(pose));
  if (team_ && pose.stamp_ns - last_team_history_ns_ >= options_.team_pose_period.nanoseconds()) {
    last_team_history_ns_ = pose.stamp_ns;
    team_history_.Add(PoseOf(pose));
  }
  // Before the filter has initialised there is no frame to map in, and it
  // would refuse a switch.
  if ((pose.status & topics::kPoseStatusNotInitialised) != 0) return;
  const Time stamp = Time::FromNanoseconds(pose.stamp_ns);
  if (slam_) {
    DecideResume(nullptr);
    EnsurePrior(pose.frame_id, pose.stamp_ns);
    latest_pose_ = pose;
    if (Time::Now() - last_global_pose_handed_ >= options_.global_pose_period) HandLatestPose();
  }
  const Eigen::Vector3d p(pose.p_local_body_m[0], pose.p_local_body_m[1], pose.p_local_body_m[2]);
  const std::optional<topics::SwitchReason> reason =
      trigger_.OnPose(stamp, pose.frame_id, p, pose.position_sigma_m);
  // The request this estimate may trigger belongs to the next frame: record
  // the estimate first.
  if (SubmapRecord* s = Current(pose.frame_id, stamp)) {
    ++s->poses;
    s->last_stamp = stamp;
    s->distance_m = trigger_.distance_m();
  }
  if (!reason) return;
  const bool sent = requests_->PublishInPlace([&](topics::FrameSwitchRequestMsg& m) {
    m.reason = *reason;
    m.request_id = next_request_id_;
    m.pose_stamp_ns = pose.stamp_ns;
    m.pose_frame_id = pose.frame_id;
  });
  if (!sent) {
    ++stats_.request_drops;
    return;
  }
  ++next_request_id_;
  ++stats_.requests;
  last_reason_ = reason;
  request_frame_ = pose.frame_id;
}

void Mapd::OnFrame(const topics::StereoFrameMsg& frame) {
  if (frame.version != topics::kTopicsVersion) {
    ++stats_.version_mismatches;
    return;
  }
  ++stats_.frames;
  if (!submaps_.empty()) ++submaps_.back().frames;
  if (!stats_.first_sequence) {
    stats_.first_sequence = frame.sequence;
    stats_.first_capture_ns = frame.capture_stamp_ns;
  }
  stats_.last_sequence = frame.sequence;
  stats_.last_capture_ns = frame.capture_stamp_ns;
  stats_.pair_bytes = 2ull * frame.width_px * frame.height_px;
  if (!pending_frame_) return;
  const Time capture = Time::FromNanoseconds(frame.capture_stamp_ns);
  if (options_.max_mapping_rate_hz > 0.0 && last_mapped_capture_ &&
      (capture - *last_mapped_capture_).ToSeconds() < 1.0 / options_.max_mapping_rate_hz) {
    ++stats_.images_skipped;
    return;
  }
  if (has_pending_) ++stats_.images_skipped;  // a newer pair replaces it
  std::swap(pending_frame_, frame_buffer_);
  has_pending_ = true;
}

void Mapd::TakeCalibration() {
  topics::StereoCalibrationMsg m;
  if (!calibration_->TryTake(&m)) return;
  if (m.version != topics::kTopicsVersion) {
    ++stats_.version_mismatches;
    return;
  }
  try {
    mapper_ =
        std::make_unique<LocalMapper>(options_.local_mapper, CameraOf(m.cam0), CameraOf(m.cam1));
    std::fprintf(stderr, "mapd: stereo calibration received (%dx%d px): mapping\n", m.cam0.width_px,
                 m.cam0.height_px);
    StartTags();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mapd: cannot map with roverd's stereo calibration: %s\n", e.what());
    calibration_.reset();  // do not retry every poll
  }
}

void Mapd::TryMapPending() {
  if (!has_pending_ || !mapper_) return;
  const Time capture = Time::FromNanoseconds(pending_frame_->capture_stamp_ns);
  const std::optional<Time> newest = history_.newest();
  if (!newest || *newest < capture) return;  // its estimates are still on the way
  has_pending_ = false;
  const std::optional<StampedPose> pose = history_.At(capture);
  if (!pose) {
    ++stats_.images_unplaced;
    return;
  }
  MapPair(*pending_frame_, *pose);
}

void Mapd::MapPair(const topics::StereoFrameMsg& frame, const StampedPose& pose) {
  // Only the frames this process saw begin are its submaps.
  if (submaps_.empty() || submaps_.back().frame_id != pose.frame_id) {
    ++stats_.images_unplaced;
    return;
  }
  if (mapping_submap_ && mapping_submap_->frame_id() != pose.frame_id) FinishMappingSubmap();
  if (!mapping_submap_) {
    mapping_submap_ =
        std::make_unique<mapping::Submap>(submaps_.back().index, pose.frame_id, options_.submap);
    mapper_->ResetTraversability();
  }
  const auto rows = static_cast<int>(frame.height_px);
  const auto cols = static_cast<int>(frame.width_px);
  // Views of the message's packed rows: no copy.
  const cv::Mat raw0(rows, cols, CV_8UC1, const_cast<uint8_t*>(frame.cam0.data()));
  const cv::Mat raw1(rows, cols, CV_8UC1, const_cast<uint8_t*>(frame.cam1.data()));
  const auto start = std::chrono::steady_clock::now();
  try {
    const MappedImage mapped =
        mapper_->Process(raw0, raw1, pose.T_local_body, mapping_submap_.get());
    stats_.obstacle_points += static_cast<uint64_t>(mapped.obstacle_points);
  } catch (const std::exception& e) {
    if (stats_.images_failed++ == 0) std::fprintf(stderr, "mapd: mapping a pair: %s\n", e.what());
    return;
  }
  stats_.mapping_ms_total +=
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  ++stats_.images_mapped;
  last_mapped_capture_ = Time::FromNanoseconds(frame.capture_stamp_ns);
  if (tags_) {
    tags_->Submit(mapper_->rectified_left(), {.stamp_ns = frame.capture_stamp_ns,
                                              .frame_id = pose.frame_id,
                                              .T_local_body = pose.T_local_body,
                                              .covariance = pose.covariance});
  }
  if (!last_traversability_ ||
      *last_mapped_capture_ - *last_traversability_ >= options_.traversability_period) {
    LogTraversability(frame.capture_stamp_ns);
    last_traversability_ = last_mapped_capture_;
  }
}

void Mapd::LogTraversability(int64_t stamp_ns) {
  const mapping::TraversabilityGrid& grid = mapper_->traversability();
  log::nav_msgs::OccupancyGrid msg;
  msg.header.stamp = log::ToRosTime(Time::FromNanoseconds(stamp_ns));
  msg.header.frame_id = log::FrameId::Truncated("local/" + options_.robot_name + "/" +
                                                std::to_string(mapping_submap_->frame_id()));
  const int n = grid.cells_per_side();
  msg.info.map_load_time = msg.header.stamp;
  msg.info.resolution = static_cast<float>(grid.resolution_m());
  msg.info.width = static_cast<uint32_t>(n);
  msg.info.height = static_cast<uint32_t>(n);
  msg.info.origin.position.x = grid.origin_xy().x();
  msg.info.origin.position.y = grid.origin_xy().y();
  msg.data.resize(static_cast<std::size_t>(n) * static_cast<std::size_t>(n));
  // h_diff / (h_max + Delta_d) of 1 (the limit) maps to 65, map_server's
  // default occupied threshold, so ROS tools draw the same boundary.
  for (int iy = 0; iy < n; ++iy) {
    for (int ix = 0; ix < n; ++ix) {
      const float v = grid.value(ix, iy);
      msg.data[static_cast<std::size_t>(iy) * static_cast<std::size_t>(n) +
               static_cast<std::size_t>(ix)] =
          v < 0.0f ? int8_t{-1} : static_cast<int8_t>(std::lround(std::min(100.0f, 65.0f * v)));
    }
  }
  archive_->LogTraversability(msg);
  if (log::SerializedSize(msg) <= topics::TraversabilityMsg::kMaxCdrBytes) {
    const bool sent = traversability_->PublishInPlace([&msg](topics::TraversabilityMsg& m) {
      m.cdr_size = static_cast<uint32_t>(log::SerializeMessage(msg, m.cdr));
    });
    if (sent) ++stats_.grids_published;
  }
}

void Mapd::FinishMappingSubmap() {
  if (!mapping_submap_) return;
  mapping_submap_->Finish();
  const SubmapRecord* record = nullptr;
  for (const SubmapRecord& r : submaps_) {
    if (r.frame_id == mapping_submap_->frame_id()) record = &r;
  }
  if (record != nullptr && mapping_submap_->images() > 0) {
    mapping::TeamSubmap messages;
    const ArchivedBytes bytes =
        archive_->Add(*record, *mapping_submap_, team_ ? &messages : nullptr);
    if (team_) team_->ShareSubmap(messages, record->last_stamp.nanoseconds());
    stats_.octree_bytes += bytes.octree;
    stats_.cloud_bytes += bytes.cloud;
    ++stats_.submaps_archived;
    // The loop closer owns it from here until its matching data is built.
    if (loop_) loop_->AddSubmap(std::shared_ptr<const mapping::Submap>(std::move(mapping_submap_)));
  }
  mapping_submap_.reset();
  // A submap's worth of memory (octree, cloud, serialised messages, the
  // previous submap's matching temporaries) has been freed by now: hand the
  // free pages of every malloc arena back to the system, so that mapd's
  // footprint follows what it holds, not its peaks, over a long mission.
  ::malloc_trim(0);
  if (record != nullptr) LogMemory(record->last_stamp.nanoseconds());
}

void Mapd::LogMemory(int64_t stamp_ns) {
  std::string error;
  const std::optional<runtime::ProcessMemory> memory = runtime::ReadProcessMemory(&error);
  if (!memory) {
    if (!memory_error_reported_)
      std::fprintf(stderr, "mapd: memory not logged: %s\n", error.c_str());
    memory_error_reported_ = true;
    return;
  }
  if (!first_memory_) first_memory_ = memory;
  last_memory_ = memory;
  log::diagnostic_msgs::DiagnosticStatus status;
  status.level = log::diagnostic_msgs::DiagnosticStatus::kOk;
  status.name = "mapd: memory";
  status.hardware_id = options_.robot_name;
  status.message = std::to_string(stats_.submaps_archived) + " submaps archived";
  status.values = memory->ToKeyValues();
  status.values.push_back({"submaps_archived", std::to_string(stats_.submaps_archived)});
  if (loop_) {
    const mapping::MatchDataStoreStats store = loop_->Stats().store;
    status.values.push_back({"match_data_held", std::to_string(store.submaps)});
    status.values.push_back({"match_data_resident", std::to_string(store.resident)});
    status.values.push_back({"match_data_spilled_kb", std::to_string(store.spilled_bytes / 1024)});
  }
  log::diagnostic_msgs::DiagnosticArray array;
  array.header.stamp = log::ToRosTime(Time::FromNanoseconds(stamp_ns));
  array.status.push_back(std::move(status));
  archive_->LogDiagnostics(array);
}

void Mapd::HandLatestPose() {
  if (!latest_pose_) return;
  last_global_pose_handed_ = Time::Now();
  const StampedPose pose = PoseOf(*latest_pose_);
  slam_->SetFilterPose(pose.stamp.nanoseconds(), pose.frame_id, pose.T_local_body, pose.covariance);
  latest_pose_.reset();
}

void Mapd::EnsurePrior(uint32_t frame_id, int64_t stamp_ns) {
  if (prior_added_) return;
  prior_added_ = true;
  prior_frame_ = frame_id;
  // The rover's world frame is the first local frame the graph sees; a tight
  // prior fixes the gauge without pulling on anything else.
  mapping::GraphFactorRecord prior =
      mapping::OriginPriorFactor(options_.robot_id, frame_id, Eigen::Isometry3d::Identity(),
                                 1e-12 * mapping::Matrix6d::Identity());
  prior.stamp_ns = stamp_ns;
  AddFactor(std::move(prior));
}

void Mapd::LoadResumeCandidate() {
  if (options_.output_stem.empty()) return;
  const std::optional<std::string> previous = PreviousMapdLog(options_.output_stem);
  if (!previous) return;
  try {
    resume_candidate_ = mapping::ReadGraphLogs({*previous});
    resume_path_ = *previous;
    for (const std::string& p : resume_candidate_->problems) {
      std::fprintf(stderr, "mapd: %s\n", p.c_str());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mapd: cannot read the previous log: %s\n", e.what());
  }
}

void Mapd::DecideResume(const topics::FrameSwitchMsg* record) {
  if (resume_decided_) return;
  resume_decided_ = true;
  if (!resume_candidate_) {
    StartTeam(nullptr);
    return;
  }
  // The same mission iff roverd's switch history holds a switch the earlier
  // graph has: same frames, same stamp to the nanosecond. Only this rover's
  // factors count; the log also holds what the team sent.
  const auto own = [this](const mapping::GraphFactorRecord& f) {
    return f.a.robot == options_.robot_id;
  };
  bool same_mission = false;
  for (const mapping::GraphFactorRecord& f : resume_candidate_->factors) {
    same_mission = same_mission ||
                   (record != nullptr && own(f) && f.kind == mapping::FactorKind::kFrameSwitch &&
                    f.a.index == record->old_frame_id && f.stamp_ns == record->stamp_ns);
  }
  if (!same_mission) {
    std::fprintf(stderr, "mapd: %s is not this mission's (no switch in common): a new graph\n",
                 resume_path_.c_str());
    resume_candidate_.reset();
    StartTeam(nullptr);
    return;
  }
  std::fprintf(stderr, "mapd: resuming the pose graph of %s (%zu factors)\n", resume_path_.c_str(),
               resume_candidate_->factors.size());
  for (std::size_t k = 0; k < resume_candidate_->factors.size(); ++k) {
    const mapping::GraphFactorRecord& f = resume_candidate_->factors[k];
    if (own(f) && f.kind == mapping::FactorKind::kPrior) {
      prior_added_ = true;
      prior_frame_ = f.a.index;
    }
    if (own(f) && f.kind == mapping::FactorKind::kFrameSwitch) switched_frames_.insert(f.a.index);
    if (own(f)) next_factor_id_ = std::max(next_factor_id_, f.id + 1);
    LogAndSubmit(resume_candidate_->messages[k]);  // this log holds the whole graph again
  }
  stats_.graph_factors_resumed = resume_candidate_->factors.size();
  StartTeam(&*resume_candidate_);
  resume_candidate_.reset();
}

void Mapd::StartTeam(const mapping::GraphLogContents* resumed) {
  if (!options_.team) return;
  team_ = std::make_unique<TeamExchange>(options_.robot_id, std::move(team_link_), *options_.team,
                                         archive_.get(), resumed);
}

void Mapd::RetryWaitingDetections(bool final) {
  const std::optional<Time> newest = history_.newest();
  std::vector<mapping::GraphFactorRecord> waiting;
  waiting.swap(waiting_detections_);
  for (const mapping::GraphFactorRecord& d : waiting) {
    if (!final && (!newest || *newest < Time::FromNanoseconds(d.stamp_ns))) {
      waiting_detections_.push_back(d);
    } else {
      AddDetectedPose(d);
    }
  }
  if (final && !waiting_detections_.empty()) {
    // Still newer than every estimate at the end: unlinked.
    stats_.detected_poses_unplaced += waiting_detections_.size();
    waiting_detections_.clear();
  }
}

void Mapd::TakeTeam() {
  TeamArrivals arrivals = team_->Take(newest_stamp_ns_);
  for (const log::rover_msgs::GraphFactor& msg : arrivals.constraints) {
    LogAndSubmit(msg);
    const mapping::GraphFactorRecord f = mapping::FromMsg(msg);  // checked on arrival
    if (f.kind == mapping::FactorKind::kRobotDetection && f.b && f.b->robot == options_.robot_id) {
      AddDetectedPose(f);
    }
  }
  if (!loop_) return;
  for (const mapping::MatchClaim& c : arrivals.claims) {
    loop_->AddClaim({c.a.robot, c.a.index}, {c.b.robot, c.b.index}, static_cast<int>(c.claimant));
  }
  for (ReceivedSubmap& s : arrivals.submaps) {
    try {
      loop_->AddTeamSubmap(
          {s.robot, s.messages.info.frame_id}, mapping::FromOctomapMsg(s.messages.octomap),
          std::make_shared<const mapping::PointCloud>(mapping::FromPointCloud2(s.messages.cloud)));
    } catch (const std::exception& e) {
      std::fprintf(stderr, "mapd: team: submap %u of robot %d cannot be read: %s\n",
                   s.messages.info.frame_id, s.robot, e.what());
    }
  }
}

void Mapd::AddFactor(mapping::GraphFactorRecord factor) {
  factor.id = next_factor_id_++;
  const log::rover_msgs::GraphFactor msg = mapping::ToMsg(factor, "graph/" + options_.robot_name);
  LogAndSubmit(msg);
  if (team_) team_->Share(msg, factor.stamp_ns);
}

void Mapd::LogAndSubmit(const log::rover_msgs::GraphFactor& msg) {
  if (archive_) archive_->LogFactor(msg);  // kept even if refused: the log is the record
  // The graph gets exactly what the log holds, so it can be rebuilt from it.
  try {
    slam_->Submit(mapping::FromMsg(msg));
  } catch (const mapping::GraphError& e) {
    ++stats_.graph_factors_refused;
    std::fprintf(stderr, "mapd: pose graph: factor left out: %s\n", e.what());
  }
}

void Mapd::PublishOrigins(const SlamSnapshot& snap) {
  const uint32_t total = static_cast<uint32_t>(snap.origins.size());
  const uint32_t per_page = topics::SubmapOriginsMsg::kMaxOrigins;
  const uint32_t pages = std::max(1u, (total + per_page - 1) / per_page);
  auto origin = snap.origins.begin();
  bool sent = true;
  for (uint32_t page = 0; page < pages; ++page) {
    sent = origins_->PublishInPlace([&](topics::SubmapOriginsMsg& m) {
      m.version = topics::kTopicsVersion;
      m.update = snap.update;
      m.stamp_ns = snap.stamp_ns;
      m.first = page * per_page;
      m.count = std::min(per_page, total - m.first);
      m.total = total;
      m.page = page;
      m.pages = pages;
      for (uint32_t k = 0; k < m.count; ++k, ++origin) {
        topics::SubmapOriginEntry& e = m.origins[k];
        e.robot = options_.robot_id;
        e.frame_id = static_cast<uint32_t>(origin->first);
        FillPose(origin->second.T_world_origin, &e.p_world_origin_m, &e.q_world_origin_wxyz);
        FillCovariance(origin->second.covariance, &e.covariance);
      }
    }) && sent;
  }
  if (sent) ++stats_.graph_states_published;
}

void Mapd::PublishGlobalPose(const SlamSnapshot& snap) {
  const bool sent = global_pose_->PublishInPlace([&](topics::GlobalPoseMsg& m) {
    m.version = topics::kTopicsVersion;
    m.robot = options_.robot_id;
    m.stamp_ns = snap.global_pose_stamp_ns;
    m.update = snap.update;
    m.frame_id = snap.global_pose_frame_id;
    FillPose(*snap.T_world_body, &m.p_world_body_m, &m.q_world_body_wxyz);
    FillCovariance(snap.global_pose_covariance, &m.covariance);
  });
  if (!sent) ++stats_.graph_publish_drops;
}

void Mapd::TakeLoopMatches() {
  for (const std::string& problem : loop_->TakeProblems()) {
    std::fprintf(stderr, "mapd: %s\n", problem.c_str());
  }
  for (const LoopMatch& m : loop_->TakeMatches()) {
    if (!m.accepted) {
      std::fprintf(stderr, "mapd: submaps %s and %s do not match: %s (%.0f ms)\n",
                   m.a.ToString().c_str(), m.b.ToString().c_str(), m.rejection.c_str(), m.match_ms);
      continue;
    }
    // How far the match moves b against the graph's estimate: the size of
    // the correction this loop closure brings.
    const Eigen::Isometry3d correction = m.prior.T_a_b.inverse() * m.T_a_b;
    std::fprintf(
        stderr,
        "mapd: loop closure between submaps %s and %s: %.2f m and %.2f deg from the "
        "graph's estimate, %s, RMSE %.3f m, %.0f ms\n",
        m.a.ToString().c_str(), m.b.ToString().c_str(), correction.translation().norm(),
        Eigen::AngleAxisd(correction.linear()).angle() * 180.0 / M_PI,
        m.from_prior ? "aligned from the prior" : (std::to_string(m.inliers) + " inliers").c_str(),
        m.rmse_m, m.match_ms);
    mapping::GraphFactorRecord factor = mapping::SubmapMatchFactor(
        mapping::GraphKey::Origin(m.a.robot, m.a.index),
        mapping::GraphKey::Origin(m.b.robot, m.b.index), m.T_a_b, m.covariance);
    // The match holds from when the later of the two submaps was finished.
    for (const SubmapRecord& r : submaps_) {
      if (r.frame_id == m.a.index || r.frame_id == m.b.index) {
        factor.stamp_ns = std::max(factor.stamp_ns, r.last_stamp.nanoseconds());
      }
    }
    AddFactor(std::move(factor));
    ++stats_.loop_closures;
    if (m.a.robot != m.b.robot) ++stats_.inter_robot_closures;
  }
  if (team_) {
    for (const auto& [a, b] : loop_->TakeClaims()) {
      team_->ShareClaim(
          {mapping::GraphKey::Origin(a.robot, a.index), mapping::GraphKey::Origin(b.robot, b.index),
           static_cast<uint32_t>(options_.robot_id)},
          newest_stamp_ns_);
    }
  }
}

void Mapd::StartTags() {
  if (!options_.tags || tags_) return;
  std::string directory = options_.tag_tables_dir;
  if (directory.empty() && !options_.output_stem.empty()) {
    directory = std::filesystem::path(options_.output_stem).parent_path().string();
  }
  const mapping::TagObserverOptions tag_options = *options_.tags;
  const calib::RectifiedIntrinsics camera = mapper_->rectified_intrinsics();
  const cv::Size size = mapper_->rectified_size();
  const bool build = options_.build_missing_tag_tables;
  tags_ = std::make_unique<TagWorker>(
      tag_options, camera, size, TagTableLoader([tag_options, camera, size, directory, build] {
        return mapping::LoadTagErrorTables(
            tag_options, camera, size, directory, build,
            [](const std::string& line) { std::fprintf(stderr, "mapd: %s\n", line.c_str()); });
      }),
      options_.tag_nice_increment);
  std::fprintf(stderr, "mapd: looking for %zu AprilTag markers (%s)\n", tag_options.markers.size(),
               tag_options.detector.families[0].c_str());
}

void Mapd::TakeTagResults() {
  if (const std::optional<std::string> error = tags_->TakeError()) {
    std::fprintf(stderr, "mapd: %s\n", error->c_str());
  }
  for (TagResult& result : tags_->TakeResults()) {
    newest_tag_stamp_ns_ = std::max(newest_tag_stamp_ns_, result.sighting.stamp_ns);
    for (mapping::TagObservation& o : result.observations) {
      HandleTagObservation(result.sighting, std::move(o));
    }
  }
  ApplyTagDecisions(tag_resolver_.Expire(newest_tag_stamp_ns_));
}

void Mapd::HandleTagObservation(const TagSighting& sighting, mapping::TagObservation o) {
  const bool landmark =
      o.marker != nullptr && o.marker->carrier == mapping::TagMarker::Carrier::kLandmark;
  const Eigen::Isometry3d T_local_cam = sighting.T_local_body * mapper_->T_body_cam();
  if (landmark && o.accepted) {
    LogTag(sighting, o);
    AddTagFactor(sighting, o);
    // It votes for where the tag is, for the ambiguous sightings.
    ApplyTagDecisions(tag_resolver_.Add(
        mapping::PlacementsOf(o, T_local_cam, 0, sighting.stamp_ns, sighting.frame_id)));
    return;
  }
  if (landmark && o.uncertainty.ambiguous && o.pose && slam_) {
    const uint64_t key = next_tag_key_++;
    const mapping::TagPlacements placements =
        mapping::PlacementsOf(o, T_local_cam, key, sighting.stamp_ns, sighting.frame_id);
    waiting_tags_.emplace(key, std::pair{sighting, std::move(o)});
    ApplyTagDecisions(tag_resolver_.Add(placements));
    return;
  }
  const bool robot =
      o.marker != nullptr && o.marker->carrier == mapping::TagMarker::Carrier::kRobot;
  if (robot && !o.accepted && o.uncertainty.ambiguous && o.inflated.accepted) {
    // A team mate's marker has no other sightings to decide its planar
    // ambiguity by (it moves): it is kept with its rotation left open, which
    // still fixes where the other rover is.
    o.uncertainty = o.inflated;
    o.accepted = true;
    o.refusal.clear();
  }
  if (o.accepted && o.marker != nullptr) {
    ++stats_.robot_tags_seen;
    // A detection joins the graph only in a team: it links this rover's map
    // to the other rover's, which only the team's graph holds.
    if (team_ && o.marker->robot != options_.robot_id) AddRobotDetection(sighting, o);
  }
  if (o.not_configured && unknown_tag_ids_.insert(o.detection.id).second) {
    std::fprintf(stderr, "mapd: AprilTag id %d is not in the marker list: ignored\n",
                 o.detection.id);
  }
  LogTag(sighting, o);
}

void Mapd::ApplyTagDecisions(const std::vector<mapping::TagDecision>& decisions) {
  for (const mapping::TagDecision& d : decisions) {
    const auto it = waiting_tags_.find(d.key);
    if (it == waiting_tags_.end()) continue;
    const TagSighting sighting = it->second.first;
    mapping::TagObservation o = std::move(it->second.second);
    waiting_tags_.erase(it);
    if (d.solution >= 0) {
      if (d.solution == 1) std::swap(o.pose->best, o.pose->alternative);
      o.pose->tilt_rad = mapping::TagTilt(o.pose->best.T_camera_tag);
      o.uncertainty = o.solutions[static_cast<std::size_t>(d.solution)];
      o.accepted = o.uncertainty.accepted;
      o.refusal = o.uncertainty.refusal;
    } else if (d.undecided && o.inflated.accepted) {
      // Nothing decided: kept with its rotation left open (both solutions
      // covered), for the position that both share.
      o.uncertainty = o.inflated;
      o.accepted = true;
      o.refusal.clear();
    } else {
      o.refusal = d.refusal;
    }
    if (d.solution >= 0) {
      ++stats_.tags_resolved;
    } else {
      (o.accepted ? stats_.tags_inflated : stats_.tags_unresolved)++;
    }
    LogTag(sighting, o);
    if (o.accepted) AddTagFactor(sighting, o);
  }
}

void Mapd::LogTag(const TagSighting& sighting, const mapping::TagObservation& o) {
  if (archive_) archive_->LogTagDetection(mapping::ToMsg(o, sighting.stamp_ns, "cam0"));
  ++stats_.tag_observations_logged;
}

bool Mapd::FrameInGraph(uint32_t frame_id) const {
  return (prior_frame_ && *prior_frame_ == frame_id) ||
         (frame_id > 0 && switched_frames_.count(frame_id - 1) > 0);
}

std::optional<int64_t> Mapd::EnsurePoseNode(const TagSighting& s) {
  if (!FrameInGraph(s.frame_id)) return std::nullopt;
  // One pose node per instant, keyed by its time in ms: unique, the same
  // after a restart, and the same key on every rover for one instant (a
  // robot detection names both rovers' poses by it).
  const int64_t pose = s.stamp_ns / 1'000'000;
  if (tag_pose_nodes_.insert(pose).second) {
    // The filter's covariance right after a frame switch is nearly zero; a
    // floor (1 mm, 0.006 deg) keeps the factor's information finite.
    mapping::Matrix6d covariance = s.covariance;
    covariance.diagonal().head<3>().array() += 1e-6;
    covariance.diagonal().tail<3>().array() += 1e-8;
    mapping::GraphFactorRecord v =
        mapping::FilterPoseFactor(options_.robot_id, s.frame_id, pose, s.T_local_body, covariance);
    v.stamp_ns = s.stamp_ns;
    AddFactor(std::move(v));
  }
  return pose;
}

void Mapd::AddTagFactor(const TagSighting& s, const mapping::TagObservation& o) {
  if (!slam_) return;
  const bool new_node = tag_pose_nodes_.count(s.stamp_ns / 1'000'000) == 0;
  const std::optional<int64_t> pose = EnsurePoseNode(s);
  if (!pose) {
    ++stats_.tag_sightings_unplaced;
    return;
  }
  if (new_node) ++stats_.tag_sightings;
  mapping::GraphFactorRecord factor = mapping::LandmarkObservationFactor(
      options_.robot_id, *pose, o.marker->landmark, mapper_->T_body_cam(),
      o.pose->best.T_camera_tag, o.uncertainty.covariance, o.marker->T_carrier_tag);
  factor.stamp_ns = s.stamp_ns;
  AddFactor(std::move(factor));
  ++stats_.tag_factors;
}

void Mapd::AddRobotDetection(const TagSighting& s, const mapping::TagObservation& o) {
  const std::optional<int64_t> pose = EnsurePoseNode(s);
  if (!pose) {
    ++stats_.robot_detections_unplaced;
    return;
  }
  // The other rover's pose at the same instant gets the same key; that rover
  // adds its filter pose there when this factor reaches it.
  mapping::GraphFactorRecord d =
      mapping::RobotDetectionFactor(options_.robot_id, *pose, o.marker->robot, *pose,
                                    {mapper_->T_body_cam(), o.pose->best.T_camera_tag,
                                     o.uncertainty.covariance, o.marker->T_carrier_tag});
  d.stamp_ns = s.stamp_ns;
  AddFactor(std::move(d));
  ++stats_.robot_detections;
}

void Mapd::AddDetectedPose(const mapping::GraphFactorRecord& d) {
  // The estimate at the detection's instant: from the recent estimates, or
  // the decimated long history when the link was slow.
  const Time stamp = Time::FromNanoseconds(d.stamp_ns);
  if (!history_.newest() || *history_.newest() < stamp) {
    // This rover's clock is behind the other's (or its estimates are late):
    // wait for the estimates of then, within bounds.
    if (waiting_detections_.size() < kMaxWaitingDetections) {
      waiting_detections_.push_back(d);
      return;
    }
  }
  std::optional<StampedPose> at = history_.At(stamp);
  if (!at) at = team_history_.At(stamp);
  if (!at || !FrameInGraph(at->frame_id) || d.b->index != d.stamp_ns / 1'000'000) {
    ++stats_.detected_poses_unplaced;
    std::fprintf(stderr,
                 "mapd: robot %d saw this rover at %.3f s, but %s: the detection stays unlinked\n",
                 d.a.robot, stamp.ToSeconds(),
                 !at ? "no estimate of then is kept" : "that estimate's frame is not in the graph");
    return;
  }
  EnsurePoseNode({d.stamp_ns, at->frame_id, at->T_local_body, at->covariance});
  ++stats_.detected_poses;
}

void Mapd::TakeSlamSnapshot() {
  for (const std::string& problem : slam_->TakeProblems()) {
    std::fprintf(stderr, "mapd: pose graph: %s\n", problem.c_str());
  }
  const SlamSnapshot snap = slam_->Latest();
  if (snap.update == last_snapshot_update_) return;
  last_snapshot_update_ = snap.update;
  // Origins change only when factors are added; the global pose follows
  // every estimate handed over.
  if (snap.origins_update != last_origins_update_) {
    last_origins_update_ = snap.origins_update;
    PublishOrigins(snap);
    if (loop_) loop_->UpdateOrigins(snap.origins, snap.team_origins);
    if (archive_) LogOrigins(snap);
  }
  if (snap.T_world_body) {
    PublishGlobalPose(snap);
    if (archive_) LogGlobalPose(snap);
    if (team_) {
      team_->SetHeartbeat({.stamp_ns = snap.global_pose_stamp_ns,
                           .submap = snap.global_pose_frame_id,
                           .T_world_body = *snap.T_world_body});
    }
  }
}

void Mapd::LogOrigins(const SlamSnapshot& snap) {
  std::map<int64_t, Eigen::Isometry3d> T_world_frame;
  log::rover_msgs::SubmapOrigins origins;
  origins.header.stamp = log::ToRosTime(Time::FromNanoseconds(snap.stamp_ns));
  origins.header.frame_id = log::FrameId::Truncated("world");
  origins.update = snap.update;
  for (const auto& [frame, o] : snap.origins) {
    T_world_frame[frame] = o.T_world_origin;
    log::rover_msgs::SubmapOrigin m;
    m.robot = options_.robot_id;
    m.submap = frame;
    m.pose = mapping::ToPoseMsg(o.T_world_origin);
    for (int i = 0; i < 36; ++i)
      m.covariance[static_cast<std::size_t>(i)] = o.covariance(i / 6, i % 6);
    origins.origins.push_back(m);
  }
  archive_->SetOrigins(T_world_frame);
  archive_->LogOrigins(origins);
}

void Mapd::LogGlobalPose(const SlamSnapshot& snap) {
  log::geometry_msgs::PoseWithCovarianceStamped pose;
  pose.header.stamp = log::ToRosTime(Time::FromNanoseconds(snap.global_pose_stamp_ns));
  pose.header.frame_id = log::FrameId::Truncated("world");
  pose.pose.pose = mapping::ToPoseMsg(*snap.T_world_body);
  const mapping::Matrix6d ros =
      mapping::RosPoseCovariance(snap.T_world_body->linear(), snap.global_pose_covariance);
  for (int i = 0; i < 36; ++i)
    pose.pose.covariance[static_cast<std::size_t>(i)] = ros(i / 6, i % 6);
  archive_->LogGlobalPose(pose);
}

MapdBandwidth Mapd::Bandwidth() const {
  MapdBandwidth b;
  const double span_s =
      static_cast<double>(stats_.last_capture_ns - stats_.first_capture_ns) * 1e-9;
  if (!stats_.first_sequence || span_s <= 0.0) return b;
  // Sequence numbers count every pair the camera captured, including those
  // mapd never took: the raw rate is the camera's.
  const double pairs = static_cast<double>(stats_.last_sequence - *stats_.first_sequence);
  b.raw_stereo_bytes_per_s = pairs * static_cast<double>(stats_.pair_bytes) / span_s;
  b.submap_bytes_per_s = static_cast<double>(stats_.octree_bytes + stats_.cloud_bytes) / span_s;
  return b;
}

void Mapd::Shutdown() {
  if (shut_down_) return;
  shut_down_ = true;
  if (archive_) FinishMappingSubmap();
  if (loop_) {
    // Every submap gets its chance at a loop closure before the final graph.
    loop_->Flush();
    TakeLoopMatches();
  }
  if (tags_) {
    tags_->Flush();
    TakeTagResults();
    tags_->Stop();
    ApplyTagDecisions(tag_resolver_.Expire(newest_tag_stamp_ns_, true));
  }
  if (team_) {
    TakeTeam();
    RetryWaitingDetections(true);
  }
  if (slam_) {
    HandLatestPose();  // the run's final global pose is the last estimate's
    slam_->Flush();
    TakeSlamSnapshot();
  }
  if (team_) team_->Stop();
  if (!archive_) return;
  FinishMappingSubmap();
  const MapdBandwidth b = Bandwidth();
  std::map<std::string, std::string> graph;
  if (slam_) {
    const SlamStats g = slam_->Stats();
    graph["graph_factors"] = std::to_string(g.factors_added);
    graph["graph_factors_refused"] = std::to_string(g.factors_refused);
    graph["graph_updates"] = std::to_string(g.updates);
    graph["graph_solves"] = std::to_string(g.solves);
    graph["graph_idle_steps"] = std::to_string(g.refinements);
    if (!g.update_ms.empty()) {
      graph["graph_update_ms_p50"] = std::to_string(stats::Percentile(g.update_ms, 50.0));
      graph["graph_update_ms_p99"] = std::to_string(stats::Percentile(g.update_ms, 99.0));
    }
  }
  if (loop_) {
    const LoopCloserStats l = loop_->Stats();
    graph["loop_submaps_suitable"] = std::to_string(l.submaps_suitable);
    graph["loop_pairs_matched"] = std::to_string(l.pairs_matched);
    graph["loop_closures"] = std::to_string(stats_.loop_closures);
    if (!l.match_ms.empty()) {
      graph["matcher_ms_p50"] = std::to_string(stats::Percentile(l.match_ms, 50.0));
      graph["matcher_ms_p99"] = std::to_string(stats::Percentile(l.match_ms, 99.0));
    }
    if (!l.data_ms.empty()) {
      graph["match_data_ms_p50"] = std::to_string(stats::Percentile(l.data_ms, 50.0));
    }
    graph["match_data_resident"] = std::to_string(l.store.resident);
    graph["match_data_spilled_bytes"] = std::to_string(l.store.spilled_bytes);
    graph["match_data_spill_reads"] = std::to_string(l.store.spill_reads);
  }
  if (tags_) {
    const TagWorkerStats t = tags_->Stats();
    graph["tag_images"] = std::to_string(t.observer.images);
    graph["tag_decoded"] = std::to_string(t.observer.decoded);
    graph["tag_accepted"] = std::to_string(t.observer.accepted);
    graph["tag_not_configured"] = std::to_string(t.observer.not_configured);
    graph["tag_refused_by_detector"] = std::to_string(t.observer.refused_by_detector);
    graph["tag_refused_by_model"] = std::to_string(t.observer.refused_by_model);
    graph["tag_images_dropped"] = std::to_string(t.dropped + t.not_ready);
    graph["tag_factors"] = std::to_string(stats_.tag_factors);
    graph["tag_sightings"] = std::to_string(stats_.tag_sightings);
    graph["tags_resolved"] = std::to_string(stats_.tags_resolved);
    graph["tags_inflated"] = std::to_string(stats_.tags_inflated);
    graph["tags_unresolved"] = std::to_string(stats_.tags_unresolved);
  }
  if (team_) {
    const TeamExchangeStats t = team_->Stats();
    graph["team_robot_id"] = std::to_string(options_.robot_id);
    graph["team_constraints_shared"] = std::to_string(t.constraints_shared);
    graph["team_constraints_received"] = std::to_string(t.constraints_received);
    graph["team_constraints_refused"] = std::to_string(t.constraints_refused);
    graph["team_undecodable"] = std::to_string(t.worker.undecodable);
    graph["team_link_bytes_sent"] = std::to_string(t.worker.link.sent_bytes);
    graph["team_link_bytes_received"] = std::to_string(t.worker.link.received_bytes);
    graph["team_link_bytes_per_s"] = std::to_string(t.link_bytes_per_s);
    graph["team_robot_detections"] = std::to_string(stats_.robot_detections);
    graph["team_inter_robot_closures"] = std::to_string(stats_.inter_robot_closures);
    graph["team_submaps_shared"] = std::to_string(t.submaps_shared);
    graph["team_submap_bytes_shared"] = std::to_string(t.submap_bytes_shared);
    graph["team_submaps_received"] = std::to_string(t.submaps_received);
    graph["team_submaps_refused"] = std::to_string(t.submaps_refused);
    graph["team_detected_poses"] = std::to_string(stats_.detected_poses);
    graph["team_detected_poses_unplaced"] = std::to_string(stats_.detected_poses_unplaced);
    graph["team_duplicate_fragments"] = std::to_string(t.worker.sync.duplicate_fragments);
    graph["team_refused_datagrams"] = std::to_string(t.worker.sync.refused_datagrams);
  }
  std::map<std::string, std::string> statistics = {
      {"submaps", std::to_string(stats_.submaps_archived)},
      {"images_mapped", std::to_string(stats_.images_mapped)},
      {"images_skipped", std::to_string(stats_.images_skipped)},
      {"images_unplaced", std::to_string(stats_.images_unplaced)},
      {"octree_bytes", std::to_string(stats_.octree_bytes)},
      {"cloud_bytes", std::to_string(stats_.cloud_bytes)},
      {"raw_stereo_bytes_per_s", std::to_string(b.raw_stereo_bytes_per_s)},
      {"submap_bytes_per_s", std::to_string(b.submap_bytes_per_s)}};
  statistics.merge(graph);
  archive_->Close(statistics);
}

std::string Mapd::log_path() const { return archive_ ? archive_->log_path() : std::string(); }

void Mapd::PublishStatus() {
  last_status_wall_ = Time::Now();
  status_->PublishInPlace([this](topics::MapdStatusMsg& m) {
    m.pid = static_cast<int32_t>(::getpid());
    m.submaps = static_cast<uint32_t>(submaps_.size());
    m.current_frame_id = trigger_.frame_id().value_or(0);
    m.poses = stats_.poses;
    m.frames = stats_.frames;
    m.missed = stats_.missed;
    m.requests = stats_.requests;
    m.submap_distance_m = trigger_.distance_m();
    if (tags_) {
      const TagWorkerStats t = tags_->Stats();
      m.tags_accepted = t.observer.accepted;
      m.tags_not_configured = t.observer.not_configured;
      m.tags_refused =
          t.observer.refused_by_detector + t.observer.refused_by_model + t.observer.no_pose;
      m.tag_images_failed = t.failed;
    }
  });
}

std::string Mapd::Summary() const {
  std::string out = "mapd: " + std::to_string(submaps_.size()) + " submaps, " +
                    std::to_string(stats_.poses) + " estimates, " + std::to_string(stats_.frames) +
                    " stereo pairs, " + std::to_string(stats_.requests) + " switch requests, " +
                    std::to_string(stats_.missed) + " queue overflows\n";
  if (archive_) {
    const MapdBandwidth b = Bandwidth();
    char text[320];
    std::snprintf(text, sizeof(text),
                  "  mapping: %llu pairs mapped (%.0f ms each), %llu skipped, %llu unplaced, "
                  "%llu failed; %llu submaps archived, %.1f KB/s as submaps against %.2f MB/s "
                  "raw stereo (%.3f %%)\n",
                  static_cast<unsigned long long>(stats_.images_mapped),
                  stats_.images_mapped > 0
                      ? stats_.mapping_ms_total / static_cast<double>(stats_.images_mapped)
                      : 0.0,
                  static_cast<unsigned long long>(stats_.images_skipped),
                  static_cast<unsigned long long>(stats_.images_unplaced),
                  static_cast<unsigned long long>(stats_.images_failed),
                  static_cast<unsigned long long>(stats_.submaps_archived),
                  b.submap_bytes_per_s / 1e3, b.raw_stereo_bytes_per_s / 1e6,
                  b.raw_stereo_bytes_per_s > 0.0
                      ? 100.0 * b.submap_bytes_per_s / b.raw_stereo_bytes_per_s
                      : 0.0);
    out += text;
  }
  if (slam_) {
    const SlamStats g = slam_->Stats();
    const double p50 = PercentileOrZero(g.update_ms, 50.0);
    const double p99 = PercentileOrZero(g.update_ms, 99.0);
    char text[240];
    std::snprintf(text, sizeof(text),
                  "  graph: %llu factors (%llu refused), %llu updates (%llu solves, %llu failed), "
                  "update %.2f ms p50, %.2f ms p99, %llu steps in idle time\n",
                  static_cast<unsigned long long>(g.factors_added),
                  static_cast<unsigned long long>(g.factors_refused),
                  static_cast<unsigned long long>(g.updates),
                  static_cast<unsigned long long>(g.solves),
                  static_cast<unsigned long long>(g.update_errors), p50, p99,
                  static_cast<unsigned long long>(g.refinements));
    out += text;
  }
  if (loop_) {
    const LoopCloserStats l = loop_->Stats();
    const double data_p50 = PercentileOrZero(l.data_ms, 50.0);
    const double match_p50 = PercentileOrZero(l.match_ms, 50.0);
    char text[360];
    std::snprintf(text, sizeof(text),
                  "  loop closures: %llu accepted of %llu pairs matched; %llu of %llu submaps "
                  "suitable (data %.0f ms p50); match %.0f ms p50; match data: %zu of %zu in "
                  "memory, %.1f MB spilled, %llu read back\n",
                  static_cast<unsigned long long>(stats_.loop_closures),
                  static_cast<unsigned long long>(l.pairs_matched),
                  static_cast<unsigned long long>(l.submaps_suitable),
                  static_cast<unsigned long long>(l.submaps), data_p50, match_p50, l.store.resident,
                  l.store.submaps, static_cast<double>(l.store.spilled_bytes) / 1e6,
                  static_cast<unsigned long long>(l.store.spill_reads));
    out += text;
    if (team_) {
      std::snprintf(text, sizeof(text),
                    "    with the team: %llu submaps from other rovers, %llu pairs with them "
                    "matched here, %llu accepted, %llu left to the rover that claimed them\n",
                    static_cast<unsigned long long>(l.team_submaps),
                    static_cast<unsigned long long>(l.team_pairs_matched),
                    static_cast<unsigned long long>(l.team_matches_accepted),
                    static_cast<unsigned long long>(l.pairs_claimed_by_others));
      out += text;
    }
  }
  if (tags_) {
    const TagWorkerStats t = tags_->Stats();
    char text[640];
    std::snprintf(
        text, sizeof(text),
        "  tags: %llu images searched (%llu dropped, %llu failed); %llu decoded: %llu "
        "accepted, %llu not in the marker list, %llu refused by the detector, %llu by "
        "the error model (of these ambiguous ones, %llu decided by the tag's other "
        "sightings, %llu kept with their rotation left open, %llu refused); %llu images "
        "-> %llu o factors (%llu tags before their "
        "frame was in the graph), %llu robot markers (%llu d factors; this rover seen by "
        "others %llu times, %llu of them unlinked)\n",
        static_cast<unsigned long long>(t.observer.images),
        static_cast<unsigned long long>(t.dropped + t.not_ready),
        static_cast<unsigned long long>(t.failed),
        static_cast<unsigned long long>(t.observer.decoded),
        static_cast<unsigned long long>(t.observer.accepted),
        static_cast<unsigned long long>(t.observer.not_configured),
        static_cast<unsigned long long>(t.observer.refused_by_detector),
        static_cast<unsigned long long>(t.observer.refused_by_model),
        static_cast<unsigned long long>(stats_.tags_resolved),
        static_cast<unsigned long long>(stats_.tags_inflated),
        static_cast<unsigned long long>(stats_.tags_unresolved),
        static_cast<unsigned long long>(stats_.tag_sightings),
        static_cast<unsigned long long>(stats_.tag_factors),
        static_cast<unsigned long long>(stats_.tag_sightings_unplaced),
        static_cast<unsigned long long>(stats_.robot_tags_seen),
        static_cast<unsigned long long>(stats_.robot_detections),
        static_cast<unsigned long long>(stats_.detected_poses + stats_.detected_poses_unplaced),
        static_cast<unsigned long long>(stats_.detected_poses_unplaced));
    out += text;
  }
  if (team_) out += team_->Summary();
  if (first_memory_ && last_memory_) {
    const auto mb = [](uint64_t bytes) { return static_cast<double>(bytes) / (1024.0 * 1024.0); };
    const auto kb_mb = [](uint64_t kb) { return static_cast<double>(kb) / 1024.0; };
    char text[300];
    std::snprintf(text, sizeof(text),
                  "  memory: RSS %.1f -> %.1f MB from the first finished submap to the last "
                  "(anonymous %.1f -> %.1f, shared %.1f -> %.1f); heap in use %.1f -> %.1f MB, "
                  "free held %.1f -> %.1f MB\n",
                  kb_mb(first_memory_->rss_kb), kb_mb(last_memory_->rss_kb),
                  kb_mb(first_memory_->rss_anon_kb), kb_mb(last_memory_->rss_anon_kb),
                  kb_mb(first_memory_->rss_shmem_kb), kb_mb(last_memory_->rss_shmem_kb),
                  mb(first_memory_->heap_in_use_bytes), mb(last_memory_->heap_in_use_bytes),
                  mb(first_memory_->heap_free_held_bytes), mb(last_memory_->heap_free_held_bytes));
    out += text;
  }
  char line[200];
  for (const SubmapRecord& s : submaps_) {
    std::snprintf(
        line, sizeof(line), "  submap %u  frame %u  %-14s %6.1f m  %7llu estimates  %5llu pairs\n",
        s.index, s.frame_id,
        s.reason ? std::string(topics::ToString(*s.reason)).c_str() : "(joined)", s.distance_m,
        static_cast<unsigned long long>(s.poses), static_cast<unsigned long long>(s.frames));
    out += line;
  }
  return out;
}

}  // namespace rover::mapd
