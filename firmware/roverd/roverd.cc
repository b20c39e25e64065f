#include "firmware/roverd/roverd.h"

#include <chrono>
#include <optional>
#include <stdexcept>
#include <string>

#include "estimator/feed/keyframe_at_filter_init.h"

namespace rover::roverd {
namespace {

void Nap() { std::this_thread::sleep_for(std::chrono::milliseconds(1)); }

// In lockstep the sensor stamps are simulated time and the monitors run on
// it too (see MonitorClock): gaps and staleness in simulated seconds.
// Latency against the wall clock would be meaningless there, and so would
// the rate check: the gate lets the camera and CAN threads run up to
// lockstep_lead ahead of the IMU, whose time the snapshots are taken at, so
// one interval's count is skewed by up to that lead.
runtime::SensorMonitorOptions MonitorOptions(const RoverdOptions& options) {
  options.health.Validate();
  runtime::SensorMonitorOptions m = options.health.sensor_monitor_options();
  m.measure_latency = !options.lockstep;
  if (options.lockstep) m.rate_warn_fraction = 0.0;
  return m;
}

double CameraRate(const RoverdOptions& options) {
  return options.camera ? options.camera->vo.checks.nominal_rate_hz : 10.0;
}

cv::Mat View(const drivers::ImageView& v) {
  return cv::Mat(v.height_px, v.width_px, CV_8UC1, const_cast<uint8_t*>(v.data), v.stride_bytes);
}

}  // namespace

void ApplyBoard(const runtime::BoardConfig& board, RoverdOptions* options) {
  options->camera_thread = board.threads.camera;
  options->can_thread = board.threads.can;
  options->vo_thread = board.threads.vo;
  options->health = board.health;
}

Roverd::Roverd(const RoverdOptions& options, const RoverdDrivers& drivers,
               const EstimatorLogChannels& channels, const RoverdOutputs& outputs)
    : options_(options),
      drivers_(drivers),
      outputs_(outputs),
      listeners_(outputs.listener, outputs.mapd_link),
      loop_(options.estimator, channels, &listeners_, options.lockstep),
      gate_(drivers.camera != nullptr && options.camera.has_value(), drivers.can != nullptr,
            options.lockstep_vo_latency, options.lockstep_lead),
      probe_(Duration::FromSeconds(1.0 / options.estimator.imu.rate_hz)),
      imu_monitor_("imu", options.estimator.imu.rate_hz, MonitorOptions(options)),
      camera_monitor_("camera", CameraRate(options), MonitorOptions(options)),
      wheel_monitor_("wheels", options.wheel_rate_hz, MonitorOptions(options)),
      notifier_(runtime::SystemdNotifier::FromEnvironment()) {
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

void Roverd::StartDevices() {
  // The IMU last: it is read first, the moment Run() begins.
  if (drivers_.can != nullptr) drivers_.can->Start();
  drivers_.imu->Start();
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
  if (outputs_.mapd_link != nullptr) start(options_.link_thread, [this] { LinkThread(); });
  start(options_.health_thread, [this] { HealthThread(); });
  notifier_.Ready();
  RoverdStats stats;
  ImuLoop(&stats);
  notifier_.Stopping();
  Stop();
  threads_.clear();     // joins
  Report(Time::Now());  // how the run ended (the health thread has stopped)
  loop_.Drain();        // inputs handed over after the last IMU sample still reach the log
  stats.frames = frames_.load();
  stats.frame_drops = frame_drops_.load();
  stats.vo_measurements = vo_measurements_.load();
  if (outputs_.images != nullptr) {
    stats.images_logged = outputs_.images->logged();
    stats.image_log_drops = outputs_.images->dropped();
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
  stats.health_reports = health_reports_;
  stats.health = last_health_;
  stats.watchdog_pings = watchdog_pings_;
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
      imu_monitor_.OnError();
      continue;
    }
    ++stats->imu_samples;
    if (last_sequence && sample.sequence > *last_sequence + 1) {
      stats->imu_drops += sample.sequence - *last_sequence - 1;
      imu_monitor_.OnDrop(sample.sequence - *last_sequence - 1);
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
    imu_monitor_.OnSample(sample.stamp, MonitorClock(sample.stamp));
    PublishFilterHealth(sample.stamp);
    if (!options_.lockstep) probe_.OnEstimatePublished(sample.stamp, done);
    if (filter_init_ns_.load(std::memory_order_relaxed) == 0 && loop_.filter().initialised()) {
      filter_init_ns_.store(sample.stamp.nanoseconds(), std::memory_order_release);
    }
    if (options_.lockstep) gate_.ImuStepped(sample.stamp);
  }
  gate_.ImuEnded();
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
    camera_monitor_.OnSample(frame.stamp, MonitorClock(frame.stamp));
    if (last_sequence && frame.sequence > *last_sequence + 1) {
      frame_drops_.fetch_add(frame.sequence - *last_sequence - 1, std::memory_order_relaxed);
      camera_monitor_.OnDrop(frame.sequence - *last_sequence - 1);
    }
    last_sequence = frame.sequence;
    if (options_.lockstep) gate_.FrameArrived(frame.stamp);
    if (!TriggerClones()) loop_.PushCloneTrigger({frame.stamp});
    if (outputs_.mapd_link != nullptr) outputs_.mapd_link->PublishFrame(frame);
    if (outputs_.images != nullptr) outputs_.images->OnFrame(frame);
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
  estimator::KeyframeAtFilterInit keyframe_at_init;
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
    if (options_.lockstep) gate_.WaitForImuAt(s.capture);
    const int64_t init_ns = filter_init_ns_.load(std::memory_order_acquire);
    const std::optional<Time> init =
        init_ns != 0 ? std::optional<Time>(Time::FromNanoseconds(init_ns)) : std::nullopt;
    if (keyframe_at_init.ShouldRequest(s.capture, init)) vo_->RequestKeyframe();
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
    outputs_.mapd_link->PollRequests(&loop_);
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
      wheel_monitor_.OnError();
      continue;
    }
    if (status != drivers::ReadStatus::kOk) continue;
    if (options_.lockstep) gate_.CanFrameArrived(frame.stamp);
    if (const auto speeds = decoder_.Feed(frame)) {
      wheel_monitor_.OnSample(speeds->stamp, MonitorClock(speeds->stamp));
      if (loop_.PushWheelSpeeds({speeds->stamp, speeds->wheel_rate_rad_s})) {
        wheel_readings_.fetch_add(1, std::memory_order_relaxed);
      }
    }
    if (options_.lockstep) gate_.CanFrameDone(frame.stamp);
  }
  gate_.CanEnded();
}

void Roverd::PublishFilterHealth(Time imu_stamp) {
  const estimator::EskfHealth& h = loop_.filter().health();
  const uint32_t status = loop_.filter().initialised() ? loop_.filter().output().status
                                                       : estimator::kStatusNotInitialised;
  filter_status_.store(status, std::memory_order_relaxed);
  relative_poses_accepted_.store(h.Accepted(estimator::InputKind::kRelativePose),
                                 std::memory_order_relaxed);
  relative_poses_rejected_.store(h.Rejected(estimator::InputKind::kRelativePose),
                                 std::memory_order_relaxed);
  wheel_speeds_accepted_.store(h.Accepted(estimator::InputKind::kWheelSpeeds),
                               std::memory_order_relaxed);
  imu_steps_.store(imu_steps_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  latest_imu_ns_.store(imu_stamp.nanoseconds(), std::memory_order_relaxed);
}

void Roverd::HealthThread() {
  // The watchdog is fed only while the IMU loop makes progress: a hung
  // estimator must get roverd restarted, a hung health thread too.
  const Duration period = options_.health.period();
  Duration wake = period;
  if (const auto ping = notifier_.watchdog_ping_period(); ping && options_.health.watchdog) {
    wake = std::min(wake, *ping);
  }
  Time next_report = Time::Now() + period;
  uint64_t last_steps = 0;
  while (!stop_.load(std::memory_order_relaxed)) {
    SleepFor(wake);
    if (stop_.load(std::memory_order_relaxed)) break;
    const uint64_t steps = imu_steps_.load(std::memory_order_relaxed);
    if (options_.health.watchdog && notifier_.watchdog_interval() && steps != last_steps) {
      if (notifier_.Watchdog()) ++watchdog_pings_;
    }
    last_steps = steps;
    const Time now = Time::Now();
    if (now < next_report) continue;
    next_report = now + period;
    Report(now);
  }
}

void Roverd::Report(Time now) {
  const runtime::HealthReport report = BuildHealthReport(now);
  // In lockstep the log runs on simulated time: stamp the report with the
  // newest estimate's time so that it sits where it belongs in the log.
  const Time stamp = options_.lockstep
                         ? Time::FromNanoseconds(latest_imu_ns_.load(std::memory_order_relaxed))
                         : now;
  const log::diagnostic_msgs::DiagnosticArray array = report.ToDiagnosticArray(stamp);
  if (outputs_.diagnostics != nullptr) outputs_.diagnostics->Log(stamp, array);
  if (outputs_.mapd_link != nullptr) outputs_.mapd_link->PublishDiagnostics(array);
  last_health_ = report.OneLine();
  notifier_.Status(last_health_);
  ++health_reports_;
}

void Roverd::SleepFor(Duration d) const {
  // In short steps, so that Stop() is noticed quickly.
  const Time until = Time::Now() + d;
  while (!stop_.load(std::memory_order_relaxed) && Time::Now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

Time Roverd::MonitorClock(Time sensor_stamp) const {
  return options_.lockstep ? sensor_stamp : Time::Now();
}

runtime::HealthReport Roverd::BuildHealthReport(Time wall_now) {
  // Lockstep: "now" is the newest estimate's simulated time.
  const Time now = options_.lockstep
                       ? Time::FromNanoseconds(latest_imu_ns_.load(std::memory_order_relaxed))
                       : wall_now;
  runtime::HealthReport report;
  report.AddSensor(imu_monitor_.Snapshot(now));
  if (vo_) report.AddSensor(camera_monitor_.Snapshot(now));
  if (drivers_.can != nullptr) report.AddSensor(wheel_monitor_.Snapshot(now));
  // The filter: degraded flags and what it accepts.
  const uint32_t status = filter_status_.load(std::memory_order_relaxed);
  runtime::HealthLevel level = runtime::HealthLevel::kOk;
  std::string message = "ok";
  if ((status & estimator::kStatusNotInitialised) != 0) {
    level = runtime::HealthLevel::kWarn;
    message = "initialising (waiting for a standstill)";
  } else if ((status & (estimator::kStatusImuGap | estimator::kStatusImuInvalid |
                        estimator::kStatusNumerical)) != 0) {
    level = runtime::HealthLevel::kError;
    message = "IMU gap, invalid IMU data or a numerical problem";
  } else if ((status & estimator::kStatusNoAiding) != 0) {
    level = runtime::HealthLevel::kWarn;
    message = "no VO or wheel update accepted recently: IMU only";
  }
  const auto n = [](uint64_t v) { return std::to_string(v); };
  report.AddStatus("estimator", level, message,
                   {{"status_flags", n(status)},
                    {"relative_poses_accepted", n(relative_poses_accepted_.load())},
                    {"relative_poses_rejected", n(relative_poses_rejected_.load())},
                    {"wheel_speeds_accepted", n(wheel_speeds_accepted_.load())}});
  // The real-time loop.
  const runtime::LatencySummary step = step_latency_.Summarize();
  const EstimatorLoopStats loop = loop_.stats();
  const auto us = [](int64_t ns) { return std::to_string(static_cast<double>(ns) / 1000.0); };
  report.AddStatus("imu loop",
                   loop.ring_drops > 0 ? runtime::HealthLevel::kWarn : runtime::HealthLevel::kOk,
                   loop.ring_drops > 0 ? "measurements dropped at full rings" : "ok",
                   {{"step_p50_us", us(step.p50_ns)},
                    {"step_p99_us", us(step.p99_ns)},
                    {"step_max_us", us(step.max_ns)},
                    {"inputs", n(loop.inputs)},
                    {"late_inputs", n(loop.late_inputs)},
                    {"ring_drops", n(loop.ring_drops)}});
  if (vo_) {
    report.AddStatus(
        "vo", runtime::HealthLevel::kOk, "ok",
        {{"relative_poses", n(vo_measurements_.load())}, {"frame_drops", n(frame_drops_.load())}});
  }
  if (outputs_.mapd_link != nullptr) {
    const bool up = outputs_.mapd_link->MapdConnected();
    const MapdLinkStats m = outputs_.mapd_link->stats();
    report.AddStatus(
        "mapd", up ? runtime::HealthLevel::kOk : runtime::HealthLevel::kWarn,
        up ? "connected" : "not connected (mapping paused; roverd unaffected)",
        {{"frame_switch_requests", n(m.requests)}, {"publish_drops", n(m.publish_drops)}});
  }
  return report;
}

}  // namespace rover::roverd
