#include "firmware/mapd/mapd.h"

#include <unistd.h>

#include <cstdio>
#include <stdexcept>

#include "estimator/eskf/eskf_output.h"

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
                                              uint64_t queue) {
  std::string error;
  auto s = transport->MakeSubscriber<T>(TopicOf(name), {.queue_capacity = queue}, &error);
  if (s == nullptr) {
    throw std::runtime_error("mapd: cannot subscribe to " + std::string(name) + ": " + error);
  }
  return s;
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

}  // namespace

Mapd::Mapd(const MapdOptions& options, ipc::Transport* transport)
    : options_(options),
      trigger_(options.trigger),
      poses_(Subscribe<topics::PoseMsg>(transport, topics::kPoseTopic, options.pose_queue)),
      // Two frames: a slow mapd works on the newest pair, never on a backlog.
      frames_(Subscribe<topics::StereoFrameMsg>(transport, topics::kStereoFrameTopic, 2)),
      switches_(Subscribe<topics::FrameSwitchMsg>(transport, topics::kFrameSwitchTopic, 16)),
      requests_(
          Advertise<topics::FrameSwitchRequestMsg>(transport, topics::kFrameSwitchRequestTopic, 0)),
      // History 1: whoever connects later sees mapd's state at once.
      status_(Advertise<topics::MapdStatusMsg>(transport, topics::kMapdStatusTopic, 1)),
      frame_buffer_(std::make_unique<topics::StereoFrameMsg>()) {
  trigger_.RequestAtNextPose();
}

Mapd::~Mapd() = default;

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
  while (frames_->TryTake(frame_buffer_.get())) {
    OnFrame(*frame_buffer_);
    ++handled;
  }
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
  submaps_.push_back(s);
  PublishStatus();
  return &submaps_.back();
}

void Mapd::OnPose(const topics::PoseMsg& pose) {
  if (pose.version != topics::kTopicsVersion) {
    ++stats_.version_mismatches;
    return;
  }
  ++stats_.poses;
  // Before the filter has initialised there is no frame to map in, and it
  // would refuse a switch.
  if ((pose.status & estimator::kStatusNotInitialised) != 0) return;
  const Time stamp = Time::FromNanoseconds(pose.stamp_ns);
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
}

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
  });
}

std::string Mapd::Summary() const {
  std::string out = "mapd: " + std::to_string(submaps_.size()) + " submaps, " +
                    std::to_string(stats_.poses) + " estimates, " + std::to_string(stats_.frames) +
                    " stereo pairs, " + std::to_string(stats_.requests) + " switch requests, " +
                    std::to_string(stats_.missed) + " queue overflows\n";
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
