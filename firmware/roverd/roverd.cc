#include "firmware/roverd/roverd.h"

#include <chrono>
#include <stdexcept>
#include <string>

namespace rover::roverd {
namespace {

void Nap() { std::this_thread::sleep_for(std::chrono::milliseconds(1)); }

cv::Mat View(const drivers::ImageView& v) {
  return cv::Mat(v.height_px, v.width_px, CV_8UC1, const_cast<uint8_t*>(v.data), v.stride_bytes);
}

}  // namespace

Roverd::Roverd(const RoverdOptions& options, const RoverdDrivers& drivers,
               const EstimatorLogChannels& channels, EstimatorListener* listener,
               MapdLink* mapd_link, ImageLogger* image_logger)
    : options_(options),
      drivers_(drivers),
      mapd_link_(mapd_link),
      image_logger_(image_logger),
      listeners_(listener, mapd_link),
      loop_(options.estimator, channels, &listeners_, options.lockstep),
      gate_(drivers.camera != nullptr && options.camera.has_value(), drivers.can != nullptr,
            options.lockstep_vo_latency, options.lockstep_lead),
      probe_(Duration::FromSeconds(1.0 / options.estimator.imu.rate_hz)) {
  if (drivers_.imu == nullptr) throw std::invalid_argument("roverd: expected an IMU driver");
  if (options_.camera && drivers_.camera != nullptr) {
    std::string error;
    vo_ = estimator::vo::StereoOdometry::Create(options_.camera->cam0, options_.camera->cam1,
                                                options_.camera->vo, &error);
    if (!vo_) throw std::invalid_argument("roverd: " + error);
    if (options_.frame_slots < 1 || options_.frame_slots > 15) {
      throw std::invalid_argument("roverd: expected 1..15 frame slots, found " +
                                  std::to_string(options_.frame_slots));
    }
    slots_.resize(static_cast<std::size_t>(options_.frame_slots));
    for (int i = 0; i < options_.frame_slots; ++i) free_slots_.TryPush(i);
  }
}

Roverd::~Roverd() {
  Stop();
  threads_.clear();  // joins
}

void Roverd::Stop() {
  stop_.store(true);
  gate_.Stop();
}

RoverdStats Roverd::Run() {
  const auto start = [this](runtime::RtThreadOptions options, std::function<void()> body) {
    if (options_.lockstep) options.priority = 0;  // the threads wait on each other
    threads_.push_back(std::make_unique<runtime::RtThread>(
        options, [body = std::move(body)](std::stop_token) { body(); }));
    thread_reports_.push_back(threads_.back()->report().Describe());
  };
  if (vo_) {
    if (TriggerClones()) {
      runtime::RtThreadOptions trigger = options_.camera_thread;
      trigger.name = "trigger";
      start(trigger, [this] { TriggerThread(); });
    }
    start(options_.camera_thread, [this] { CameraThread(); });
    start(options_.vo_thread, [this] { VoThread(); });
  }
  if (drivers_.can != nullptr) start(options_.can_thread, [this] { CanThread(); });
  if (mapd_link_ != nullptr) start(options_.link_thread, [this] { LinkThread(); });
  RoverdStats stats;
  ImuLoop(&stats);
  Stop();
  threads_.clear();  // joins
  loop_.Drain();     // inputs handed over after the last IMU sample still reach the log
  stats.frames = frames_.load();
  stats.frame_drops = frame_drops_.load();
  stats.vo_measurements = vo_measurements_.load();
  if (image_logger_ != nullptr) {
    stats.images_logged = image_logger_->logged();
    stats.image_log_drops = image_logger_->dropped();
  }
  if (vo_) stats.vo = vo_->health();
  stats.wheel_readings = wheel_readings_.load();
  stats.can = decoder_.stats();
  stats.can_errors = can_errors_.load();
  stats.loop = loop_.stats();
  stats.filter = loop_.filter().health();
  stats.step_latency = step_latency_.Summarize();
  stats.sample_to_estimate = probe_.sample_to_estimate().Summarize();
  stats.sample_to_read = probe_.wakeup_latency().Summarize();
  stats.thread_reports = thread_reports_;
  return stats;
}

void Roverd::ImuLoop(RoverdStats* stats) {
  std::optional<uint64_t> last_sequence;
  drivers::ImuSample sample;
  while (!stop_.load(std::memory_order_relaxed)) {
    const drivers::ReadStatus status = drivers_.imu->Read(&sample, options_.read_timeout);
    if (status == drivers::ReadStatus::kEndOfStream) break;
    if (status == drivers::ReadStatus::kTimeout) continue;
    if (status == drivers::ReadStatus::kError) {
      ++stats->imu_errors;
      continue;
    }
    ++stats->imu_samples;
    if (last_sequence && sample.sequence > *last_sequence + 1) {
      stats->imu_drops += sample.sequence - *last_sequence - 1;
    }
    last_sequence = sample.sequence;
    if (options_.lockstep) gate_.WaitBeforeImu(sample.stamp);
    const Time start = Time::Now();
    // With real sensors the stamps are on CLOCK_MONOTONIC: how old the sample
    // is when read, and when its estimate is out, are the loop's latencies.
    if (!options_.lockstep) probe_.OnWake(sample.stamp, start);
    loop_.Step({sample.stamp, sample.angular_velocity_rad_s, sample.linear_acceleration_m_s2});
    const Time done = Time::Now();
    step_latency_.Record((done - start).nanoseconds());
    if (!options_.lockstep) probe_.OnEstimatePublished(sample.stamp, done);
    if (filter_init_ns_.load(std::memory_order_relaxed) == 0 && loop_.filter().initialised()) {
      filter_init_ns_.store(sample.stamp.nanoseconds(), std::memory_order_release);
    }
  }
}

int Roverd::AcquireSlot() {
  int slot = -1;
  while (!free_slots_.TryPop(&slot)) {
    if (!options_.lockstep || stop_.load(std::memory_order_relaxed)) return -1;
    Nap();  // lockstep: wait for the VO rather than drop
  }
  return slot;
}

void Roverd::CameraThread() {
  drivers::StereoFrame frame;
  std::optional<uint64_t> last_sequence;
  while (!stop_.load(std::memory_order_relaxed)) {
    const drivers::ReadStatus status = drivers_.camera->Next(&frame, options_.read_timeout);
    if (status == drivers::ReadStatus::kEndOfStream) break;
    if (status != drivers::ReadStatus::kOk) continue;
    frames_.fetch_add(1, std::memory_order_relaxed);
    if (last_sequence && frame.sequence > *last_sequence + 1) {
      frame_drops_.fetch_add(frame.sequence - *last_sequence - 1, std::memory_order_relaxed);
    }
    last_sequence = frame.sequence;
    if (options_.lockstep) gate_.FrameArrived(frame.stamp);
    if (!TriggerClones()) loop_.PushCloneTrigger({frame.stamp});
    if (mapd_link_ != nullptr) mapd_link_->PublishFrame(frame);
    if (image_logger_ != nullptr) image_logger_->OnFrame(frame);
    const int slot = AcquireSlot();
    if (slot < 0) {
      frame_drops_.fetch_add(1, std::memory_order_relaxed);
      if (options_.lockstep) gate_.FrameSkipped(frame.stamp);
      drivers_.camera->Release(frame);
      continue;
    }
    FrameSlot& s = slots_[static_cast<std::size_t>(slot)];
    s.capture = frame.stamp;
    View(frame.cam0).copyTo(s.cam0);
    if (frame.cam1.data != nullptr) {
      View(frame.cam1).copyTo(s.cam1);
    } else {
      s.cam1.release();  // the VO counts a missing right image
    }
    drivers_.camera->Release(frame);
    if (options_.lockstep) gate_.FrameQueued(frame.stamp);
    to_vo_.TryPush(slot);  // never full: it holds at most frame_slots entries
  }
  gate_.CameraEnded();
}

void Roverd::TriggerThread() {
  Time stamp;
  while (!stop_.load(std::memory_order_relaxed)) {
    const drivers::ReadStatus status = drivers_.trigger->Next(&stamp, options_.read_timeout);
    if (status == drivers::ReadStatus::kEndOfStream) break;
    if (status == drivers::ReadStatus::kOk) loop_.PushCloneTrigger({stamp});
  }
}

void Roverd::VoThread() {
  bool keyframe_requested = false;
  while (true) {
    int slot = -1;
    if (!to_vo_.TryPop(&slot)) {
      if (stop_.load(std::memory_order_relaxed)) return;
      Nap();
      continue;
    }
    // Real time: a VO that fell behind takes the newest pair and drops the
    // older ones. Working off a backlog would only make every result late
    // (and, past the filter's max delay, useless); the clones of the skipped
    // frames are marginalised by the next measurement.
    int newer = -1;
    while (!options_.lockstep && to_vo_.TryPop(&newer)) {
      free_slots_.TryPush(slot);
      frame_drops_.fetch_add(1, std::memory_order_relaxed);
      slot = newer;
    }
    FrameSlot& s = slots_[static_cast<std::size_t>(slot)];
    // The filter holds clones only from its initialisation on: a keyframe
    // captured before cannot be used, so ask for one captured after it.
    const int64_t init_ns = filter_init_ns_.load(std::memory_order_acquire);
    if (!keyframe_requested && init_ns != 0 && s.capture.nanoseconds() > init_ns) {
      vo_->RequestKeyframe();
      keyframe_requested = true;
    }
    estimator::vo::StereoImages images;
    images.capture = s.capture;
    images.cam0 = s.cam0;
    images.cam1 = s.cam1;
    const estimator::vo::VoFrameResult r = vo_->Process(images);
    if (r.measurement) {
      estimator::RelativePoseMeasurement m = *r.measurement;
      m.stamp = options_.lockstep ? s.capture + options_.lockstep_vo_latency : Time::Now();
      if (loop_.PushRelativePose(m)) vo_measurements_.fetch_add(1, std::memory_order_relaxed);
    }
    free_slots_.TryPush(slot);
    if (options_.lockstep) gate_.FrameDone();
  }
}

void Roverd::LinkThread() {
  const auto period = std::chrono::nanoseconds(options_.link_poll_period.nanoseconds());
  while (!stop_.load(std::memory_order_relaxed)) {
    mapd_link_->PollRequests(&loop_);
    std::this_thread::sleep_for(period);
  }
}

void Roverd::CanThread() {
  drivers::CanFrame frame;
  while (!stop_.load(std::memory_order_relaxed)) {
    const drivers::ReadStatus status = drivers_.can->Receive(&frame, options_.read_timeout);
    if (status == drivers::ReadStatus::kEndOfStream) break;
    if (status == drivers::ReadStatus::kError) {
      can_errors_.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    if (status != drivers::ReadStatus::kOk) continue;
    if (options_.lockstep) gate_.CanFrameArrived(frame.stamp);
    if (const auto speeds = decoder_.Feed(frame)) {
      if (loop_.PushWheelSpeeds({speeds->stamp, speeds->wheel_rate_rad_s})) {
        wheel_readings_.fetch_add(1, std::memory_order_relaxed);
      }
    }
    if (options_.lockstep) gate_.CanFrameDone(frame.stamp);
  }
  gate_.CanEnded();
}

}  // namespace rover::roverd
