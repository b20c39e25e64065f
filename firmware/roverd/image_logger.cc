#include "firmware/roverd/image_logger.h"

#include <cmath>
#include <cstring>
#include <stdexcept>

namespace rover::roverd {

ImageLogMode ParseImageLogMode(const std::string& text) {
  if (text == "none") return ImageLogMode::kNone;
  if (text == "thumbnails") return ImageLogMode::kThumbnails;
  if (text == "full") return ImageLogMode::kFull;
  throw std::invalid_argument("log.images: expected none, thumbnails or full, found '" + text +
                              "'");
}

void ImageLogOptions::Validate() const {
  if (thumbnail_width_px < 16 || thumbnail_width_px > 320) {
    throw std::invalid_argument("log.thumbnail_width_px: expected 16..320, found " +
                                std::to_string(thumbnail_width_px));
  }
  if (!(std::isfinite(thumbnail_rate_hz) && thumbnail_rate_hz > 0.0)) {
    throw std::invalid_argument("log.thumbnail_rate_hz: expected a positive rate, found " +
                                std::to_string(thumbnail_rate_hz));
  }
}

ImageLogger::ImageLogger(const ImageLogOptions& options, log::FlightLog* flight_log)
    : options_(options) {
  options_.Validate();
  message_.encoding = "mono8";  // short: stays in the string's inline buffer
  if (options_.mode == ImageLogMode::kThumbnails) {
    thumbnail_ = flight_log->AddChannel<log::sensor_msgs::Image, kThumbnailSlotBytes, 16>(
        "/camera/cam0/thumbnail");
    message_.data.reserve(kThumbnailSlotBytes);
  } else if (options_.mode == ImageLogMode::kFull) {
    cam0_ = flight_log->AddChannel<log::sensor_msgs::Image, kFullSlotBytes, 16>(
        "/camera/cam0/image_raw");
    cam1_ = flight_log->AddChannel<log::sensor_msgs::Image, kFullSlotBytes, 16>(
        "/camera/cam1/image_raw");
    message_.data.reserve(static_cast<std::size_t>(kMaxWidthPx) * kMaxHeightPx);
  }
}

void ImageLogger::OnFrame(const drivers::StereoFrame& frame) {
  if (thumbnail_ != nullptr) LogThumbnail(frame);
  if (cam0_ != nullptr) {
    LogFull(cam0_, frame.cam0, frame.stamp, "cam0");
    if (frame.cam1.data != nullptr) LogFull(cam1_, frame.cam1, frame.stamp, "cam1");
  }
}

void ImageLogger::LogThumbnail(const drivers::StereoFrame& frame) {
  const drivers::ImageView& v = frame.cam0;
  if (v.data == nullptr || v.width_px <= 0 || v.height_px <= 0) return;
  if (started_ && frame.stamp < next_thumbnail_) return;
  started_ = true;
  next_thumbnail_ = frame.stamp + Duration::FromSeconds(1.0 / options_.thumbnail_rate_hz);
  // An integer factor keeps every thumbnail pixel the plain mean of a block.
  const int factor =
      std::max(1, (v.width_px + options_.thumbnail_width_px / 2) / options_.thumbnail_width_px);
  const int w = v.width_px / factor;
  const int h = v.height_px / factor;
  const auto size = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  if (size + 4096 > kThumbnailSlotBytes) {
    ++dropped_;
    return;
  }
  message_.data.resize(size);  // within the reserved capacity: no allocation
  const int area = factor * factor;
  for (int r = 0; r < h; ++r) {
    for (int c = 0; c < w; ++c) {
      int sum = 0;
      for (int dr = 0; dr < factor; ++dr) {
        const uint8_t* row = v.data + static_cast<std::size_t>(r * factor + dr) * v.stride_bytes +
                             static_cast<std::size_t>(c * factor);
        for (int dc = 0; dc < factor; ++dc) sum += row[dc];
      }
      message_.data[static_cast<std::size_t>(r * w + c)] =
          static_cast<uint8_t>((sum + area / 2) / area);
    }
  }
  message_.header.stamp = log::ToRosTime(frame.stamp);
  message_.header.frame_id = log::FrameId::Truncated("cam0");
  message_.width = static_cast<uint32_t>(w);
  message_.height = static_cast<uint32_t>(h);
  message_.step = static_cast<uint32_t>(w);
  if (thumbnail_->Log(frame.stamp, message_)) {
    ++logged_;
  } else {
    ++dropped_;
  }
}

bool ImageLogger::LogFull(log::LogChannel<log::sensor_msgs::Image, kFullSlotBytes, 16>* channel,
                          const drivers::ImageView& v, Time stamp, const char* frame_id) {
  if (v.data == nullptr || v.width_px <= 0 || v.height_px <= 0 || v.width_px > kMaxWidthPx ||
      v.height_px > kMaxHeightPx) {
    ++dropped_;
    return false;
  }
  const auto w = static_cast<std::size_t>(v.width_px);
  message_.data.resize(w * static_cast<std::size_t>(v.height_px));
  for (int r = 0; r < v.height_px; ++r) {
    std::memcpy(message_.data.data() + static_cast<std::size_t>(r) * w,
                v.data + static_cast<std::size_t>(r) * v.stride_bytes, w);
  }
  message_.header.stamp = log::ToRosTime(stamp);
  message_.header.frame_id = log::FrameId::Truncated(frame_id);
  message_.width = static_cast<uint32_t>(v.width_px);
  message_.height = static_cast<uint32_t>(v.height_px);
  message_.step = static_cast<uint32_t>(v.width_px);
  if (channel->Log(stamp, message_)) {
    ++logged_;
    return true;
  }
  ++dropped_;
  return false;
}

}  // namespace rover::roverd
