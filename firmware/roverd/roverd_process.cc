#include "firmware/roverd/roverd_process.h"

#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "firmware/runtime/log_service/log_service.h"
#include "firmware/runtime/rt/rt_setup.h"

namespace rover::roverd {

log::FlightLogOptions RoverdProcess::LogOptions(bool lockstep, const RoverdProcess* self) {
  log::FlightLogOptions o;
  // In lockstep the data carry simulated time; the log's own health records
  // follow it (the writer thread starts after roverd_ exists).
  if (lockstep) {
    o.record_clock = [self] {
      return self->roverd_ ? self->roverd_->latest_imu_stamp() : Time::Zero();
    };
  }
  return o;
}

RoverdProcess::RoverdProcess(const RoverdOptions& roverd_options, const RoverdDrivers& drivers,
                             const RoverdProcessOptions& options, EstimatorListener* listener)
    : options_(options),
      lockstep_(roverd_options.lockstep),
      flight_log_(LogOptions(roverd_options.lockstep, this)) {
  if (!lockstep_ && options_.lock_memory) {
    // Before the sensors start (locking takes a while); without the
    // privileges it degrades, and says so once.
    const runtime::RtSetupReport setup =
        runtime::RtSetup::Apply({.program_name = options_.program_name});
    if (!setup.warning.empty()) std::fprintf(stderr, "%s\n", setup.warning.c_str());
  }
  const std::filesystem::path log_path(options_.log_path);
  if (log_path.has_parent_path()) std::filesystem::create_directories(log_path.parent_path());
  std::filesystem::remove(log_path);
  flight_log_.Open(options_.log_path);
  for (const auto& [name, values] : options_.metadata) flight_log_.WriteMetadata(name, values);
  const EstimatorLogChannels channels =
      EstimatorLogChannels::Add(&flight_log_, roverd_options.estimator);
  images_ = std::make_unique<ImageLogger>(options_.images, &flight_log_);
  DiagnosticsChannel* diagnostics =
      flight_log_.AddChannel<log::diagnostic_msgs::DiagnosticArray, 16384, 64>("/diagnostics");
  if (!options_.ipc_runtime_name.empty()) {
    std::string error;
    transport_ = ipc::IceoryxTransport::Create(
        {.runtime_name = options_.ipc_runtime_name, .roudi_wait_timeout = options_.roudi_wait},
        &error);
    if (transport_ == nullptr) throw std::runtime_error(error);
    std::optional<runtime::topics::StereoCalibrationMsg> calibration;
    if (roverd_options.camera) {
      calibration = ToCalibrationMsg(roverd_options.camera->cam0, roverd_options.camera->cam1);
    }
    mapd_link_.emplace(transport_.get(), calibration);
  }
  roverd_ = std::make_unique<Roverd>(roverd_options, drivers, channels,
                                     RoverdOutputs{.listener = listener,
                                                   .mapd_link = mapd_link_ ? &*mapd_link_ : nullptr,
                                                   .images = images_.get(),
                                                   .diagnostics = diagnostics});
  flight_log_.Start();
  if (options_.log_service) {
    // Serves the log folder, this log included up to its last complete chunk.
    log_service_ = std::make_unique<runtime::LogService>(*options_.log_service);
    log_service_->Start();
  }
}

RoverdProcess::~RoverdProcess() {
  if (log_service_) log_service_->Stop();
  flight_log_.Stop();  // its writer reads roverd_ (record_clock): stop it first
}

RoverdProcessResult RoverdProcess::Run() {
  RoverdProcessResult result;
  // Here, not in the IMU thread: a device that fails to start is an error
  // for main() to report, like one that fails to open.
  roverd_->StartDevices();
  if (lockstep_) {
    result.stats = roverd_->Run();
  } else {
    // Real time: the IMU loop gets its SCHED_FIFO thread (DESIGN.md).
    runtime::RtThread imu_thread(options_.imu_thread,
                                 [&](std::stop_token) { result.stats = roverd_->Run(); });
    imu_thread.Join();
    result.stats.thread_reports.insert(result.stats.thread_reports.begin(),
                                       imu_thread.report().Describe());
  }
  if (mapd_link_) result.mapd_link = mapd_link_->stats();
  if (log_service_) result.log_service_port = log_service_->port();
  flight_log_.Stop();
  result.log = flight_log_.stats();
  if (!result.log.error.empty()) {
    throw std::runtime_error(options_.log_path + ": " + result.log.error);
  }
  return result;
}

}  // namespace rover::roverd
