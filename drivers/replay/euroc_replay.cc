#include "drivers/replay/euroc_replay.h"

#include <opencv2/imgcodecs.hpp>

#include <thread>

namespace rover::drivers {
namespace {

ImageView ViewOf(const cv::Mat& m) { return {m.cols, m.rows, m.step[0], m.ptr<uint8_t>()}; }

}  // namespace

ReplayClock::ReplayClock(bool realtime, Time dataset_start)
    : realtime_(realtime), dataset_start_(dataset_start), wall_start_(Time::Now()) {}

bool ReplayClock::WaitUntilDue(Time stamp, Duration timeout) const {
  if (!realtime_) return true;
  const Time due = wall_start_ + (stamp - dataset_start_);
  const Time now = Time::Now();
  if (due <= now) return true;
  if (due - now > timeout) {
    std::this_thread::sleep_for(std::chrono::nanoseconds(timeout.nanoseconds()));
    return false;
  }
  std::this_thread::sleep_for(std::chrono::nanoseconds((due - now).nanoseconds()));
  return true;
}

EurocImuReplay::EurocImuReplay(const EurocDataset& dataset, const ReplayClock& clock)
    : dataset_(dataset), clock_(clock) {}

ReadStatus EurocImuReplay::Read(ImuSample* sample, Duration timeout) {
  if (next_ >= dataset_.imu().size()) return ReadStatus::kEndOfStream;
  const ImuSample& s = dataset_.imu()[next_];
  if (!clock_.WaitUntilDue(s.stamp, timeout)) return ReadStatus::kTimeout;
  *sample = s;
  ++next_;
  return ReadStatus::kOk;
}

EurocStereoReplay::EurocStereoReplay(const EurocDataset& dataset, const ReplayClock& clock)
    : dataset_(dataset), clock_(clock) {}

ReadStatus EurocStereoReplay::Next(StereoFrame* frame, Duration timeout) {
  if (next_ >= dataset_.stereo_frames().size()) return ReadStatus::kEndOfStream;
  const StereoFrameFiles& files = dataset_.stereo_frames()[next_];
  if (!clock_.WaitUntilDue(files.stamp, timeout)) return ReadStatus::kTimeout;
  auto& pair = buffers_[next_ % buffers_.size()];
  const std::size_t index = next_++;
  const calib::CameraModel* calibrations[2] = {&dataset_.cam0(), &dataset_.cam1()};
  const std::string* paths[2] = {&files.cam0_path, &files.cam1_path};
  for (int i = 0; i < 2; ++i) {
    pair[static_cast<std::size_t>(i)] = cv::imread(*paths[i], cv::IMREAD_GRAYSCALE);
    const cv::Mat& image = pair[static_cast<std::size_t>(i)];
    if (image.empty()) {
      error_ = *paths[i] + ": cannot decode image";
      return ReadStatus::kError;
    }
    if (image.cols != calibrations[i]->width_px || image.rows != calibrations[i]->height_px) {
      error_ = *paths[i] + ": image is " + std::to_string(image.cols) + "x" +
               std::to_string(image.rows) + ", calibration says " +
               std::to_string(calibrations[i]->width_px) + "x" +
               std::to_string(calibrations[i]->height_px);
      return ReadStatus::kError;
    }
  }
  frame->stamp = files.stamp;
  frame->sequence = index;
  frame->cam0 = ViewOf(pair[0]);
  frame->cam1 = ViewOf(pair[1]);
  return ReadStatus::kOk;
}

void EurocStereoReplay::Release(const StereoFrame& /*frame*/) {
  // Buffers are recycled round-robin; nothing to free.
}

}  // namespace rover::drivers
