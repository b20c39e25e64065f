#ifndef ROVER_FIRMWARE_ROVERD_IMAGE_LOGGER_H_
#define ROVER_FIRMWARE_ROVERD_IMAGE_LOGGER_H_

// Camera images in the flight log (sensor_msgs/Image, mono8), from the
// camera thread. Three settings (board config `log.images`):
//   none        no images (the estimator inputs alone replay the filter)
//   thumbnails  cam0 shrunk to about `thumbnail_width_px` (box filter, an
//               integer factor) at most `thumbnail_rate_hz`: enough to see
//               what the rover saw, at a few kB/s
//   full        both images of every pair, as captured (7 MB/s at 752x480
//               and 10 Hz: for short bench runs and dataset recording)
// Real-time contract: OnFrame never allocates (the messages' buffers are
// reserved at construction for the largest image the channels take) and
// never blocks; a full log ring drops the image and the log counts it.

#include <cstdint>
#include <string>

#include "core/log/flight/flight_log.h"
#include "core/log/msgs/sensor_msgs.h"
#include "drivers/camera/stereo_frame.h"

namespace rover::roverd {

enum class ImageLogMode { kNone, kThumbnails, kFull };

/// "none" | "thumbnails" | "full"; throws std::invalid_argument otherwise.
ImageLogMode ParseImageLogMode(const std::string& text);

struct ImageLogOptions {
  ImageLogMode mode = ImageLogMode::kThumbnails;
  int thumbnail_width_px = 188;
  double thumbnail_rate_hz = 1.0;

  /// Throws std::invalid_argument: thumbnail width outside 16..320 px, or a
  /// rate that is not positive and finite.
  void Validate() const;
};

class ImageLogger {
 public:
  /// Largest image logged in full (the StereoFrameMsg limit).
  static constexpr int kMaxWidthPx = 1280;
  static constexpr int kMaxHeightPx = 800;
  static constexpr std::size_t kFullSlotBytes = 1280 * 800 + 4096;
  static constexpr std::size_t kThumbnailSlotBytes = 96 * 1024;

  /// Registers the channels (between FlightLog::Open and Start):
  /// /camera/cam0/thumbnail, or /camera/cam0/image_raw and
  /// /camera/cam1/image_raw.
  ImageLogger(const ImageLogOptions& options, log::FlightLog* flight_log);

  /// Camera thread: logs what the mode asks for from this pair.
  void OnFrame(const drivers::StereoFrame& frame);

  uint64_t logged() const { return logged_; }
  /// Images the channels refused (full ring, or larger than kMax*).
  uint64_t dropped() const { return dropped_; }

 private:
  void LogThumbnail(const drivers::StereoFrame& frame);
  bool LogFull(log::LogChannel<log::sensor_msgs::Image, kFullSlotBytes, 16>* channel,
               const drivers::ImageView& view, Time stamp, const char* frame_id);

  ImageLogOptions options_;
  log::LogChannel<log::sensor_msgs::Image, kThumbnailSlotBytes, 16>* thumbnail_ = nullptr;
  log::LogChannel<log::sensor_msgs::Image, kFullSlotBytes, 16>* cam0_ = nullptr;
  log::LogChannel<log::sensor_msgs::Image, kFullSlotBytes, 16>* cam1_ = nullptr;
  log::sensor_msgs::Image message_;  // reused: its buffer is reserved once
  Time next_thumbnail_;
  bool started_ = false;
  uint64_t logged_ = 0;
  uint64_t dropped_ = 0;
};

}  // namespace rover::roverd

#endif  // ROVER_FIRMWARE_ROVERD_IMAGE_LOGGER_H_
