#include "drivers/camera/pixel_format_converter.h"

#include <linux/videodev2.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

namespace rover::drivers {
namespace {

constexpr int kMaxSidePx = 16384;
constexpr int kMaxSlots = VIDEO_MAX_FRAME;

/// Bytes one pixel occupies in a row of the capture buffer (0: compressed).
std::size_t BytesPerPixel(uint32_t fourcc) {
  switch (fourcc) {
    case V4L2_PIX_FMT_GREY:
      return 1;
    case V4L2_PIX_FMT_Y10:
    case V4L2_PIX_FMT_Y12:
    case V4L2_PIX_FMT_Y16:
    case V4L2_PIX_FMT_YUYV:
      return 2;
    default:
      return 0;
  }
}

int ShiftBits(uint32_t fourcc) {
  switch (fourcc) {
    case V4L2_PIX_FMT_Y10:
      return 2;
    case V4L2_PIX_FMT_Y12:
      return 4;
    default:
      return 8;
  }
}

}  // namespace

std::string FourccToString(uint32_t fourcc) {
  // V4L2 marks big-endian variants with bit 31 ("Y16 -BE").
  const bool big_endian = (fourcc & (1u << 31)) != 0;
  const uint32_t code = fourcc & ~(1u << 31);
  std::string text;
  for (int i = 0; i < 4; ++i) {
    const auto c = static_cast<char>((code >> (8 * i)) & 0xFFu);
    text.push_back(c >= 0x20 && c < 0x7F ? c : '?');
  }
  while (!text.empty() && text.back() == ' ') text.pop_back();
  if (big_endian) text += "-BE";
  return text;
}

uint32_t FourccFromString(const std::string& text) {
  if (text.empty() || text.size() > 4) {
    throw std::invalid_argument(
        "fourcc: expected 1 to 4 characters (e.g. GREY, Y16, YUYV, MJPG), found '" + text + "'");
  }
  uint32_t fourcc = 0;
  for (std::size_t i = 0; i < 4; ++i) {
    const char c = i < text.size() ? text[i] : ' ';
    if (c < 0x20 || c >= 0x7F) {
      throw std::invalid_argument("fourcc: expected printable characters, found '" + text + "'");
    }
    fourcc |= static_cast<uint32_t>(static_cast<unsigned char>(c)) << (8 * i);
  }
  return fourcc;
}

bool PixelFormatConverter::Supports(uint32_t fourcc) {
  return BytesPerPixel(fourcc) != 0 || fourcc == V4L2_PIX_FMT_MJPEG;
}

PixelFormatConverter::PixelFormatConverter(uint32_t fourcc, int width_px, int height_px,
                                           std::size_t bytes_per_line, int slots)
    : fourcc_(fourcc), width_px_(width_px), height_px_(height_px), bytes_per_line_(bytes_per_line) {
  if (!Supports(fourcc)) {
    throw std::invalid_argument(
        "PixelFormatConverter: expected GREY, Y10, Y12, Y16, YUYV or MJPG, found '" +
        FourccToString(fourcc) + "'");
  }
  if (width_px < 1 || height_px < 1 || width_px > kMaxSidePx || height_px > kMaxSidePx) {
    throw std::invalid_argument(
        "PixelFormatConverter: expected a size from 1x1 to 16384x16384, found " +
        std::to_string(width_px) + "x" + std::to_string(height_px));
  }
  if (slots < 1 || slots > kMaxSlots) {
    throw std::invalid_argument("PixelFormatConverter: expected 1 to " + std::to_string(kMaxSlots) +
                                " slots, found " + std::to_string(slots));
  }
  const auto width = static_cast<std::size_t>(width_px);
  const auto height = static_cast<std::size_t>(height_px);
  const std::size_t row_bytes = width * BytesPerPixel(fourcc);
  if (fourcc == V4L2_PIX_FMT_MJPEG) {
    min_frame_bytes_ = 1;
  } else {
    if (bytes_per_line < row_bytes) {
      throw std::invalid_argument(
          "PixelFormatConverter: expected bytes_per_line >= " + std::to_string(row_bytes) +
          " for " + FourccToString(fourcc) + " at width " + std::to_string(width_px) + ", found " +
          std::to_string(bytes_per_line));
    }
    min_frame_bytes_ = bytes_per_line * (height - 1) + row_bytes;
  }
  if (fourcc != V4L2_PIX_FMT_GREY) {
    images_.resize(static_cast<std::size_t>(slots));
    for (std::vector<uint8_t>& image : images_) image.assign(width * height, 0);
  }
}

bool PixelFormatConverter::real_time_safe() const { return fourcc_ != V4L2_PIX_FMT_MJPEG; }

bool PixelFormatConverter::zero_copy() const { return fourcc_ == V4L2_PIX_FMT_GREY; }

bool PixelFormatConverter::Convert(const uint8_t* data, std::size_t bytes_used, int slot,
                                   ImageView* out) {
  if (data == nullptr || bytes_used < min_frame_bytes_ || slot < 0 || slot >= kMaxSlots)
    return false;
  const auto width = static_cast<std::size_t>(width_px_);
  if (fourcc_ == V4L2_PIX_FMT_GREY) {
    *out = ImageView{width_px_, height_px_, bytes_per_line_, data};
    return true;
  }
  if (static_cast<std::size_t>(slot) >= images_.size()) return false;
  uint8_t* dst = images_[static_cast<std::size_t>(slot)].data();
  switch (fourcc_) {
    case V4L2_PIX_FMT_Y10:
    case V4L2_PIX_FMT_Y12:
    case V4L2_PIX_FMT_Y16:
      Mono16ToMono8(data, bytes_per_line_, width_px_, height_px_, ShiftBits(fourcc_), dst, width);
      break;
    case V4L2_PIX_FMT_YUYV:
      YuyvToMono8(data, bytes_per_line_, width_px_, height_px_, dst, width);
      break;
    case V4L2_PIX_FMT_MJPEG: {
      // imdecode allocates its result (and its decoder) anyway. Decoding
      // straight into the slot's memory is not an option: on a buffer it
      // cannot decode, imdecode leaves a given output untouched instead of
      // emptying it, so the previous image would pass for this frame.
      const cv::Mat compressed(1, static_cast<int>(bytes_used), CV_8UC1,
                               const_cast<uint8_t*>(data));
      cv::Mat decoded;
      try {
        decoded = cv::imdecode(compressed, cv::IMREAD_GRAYSCALE | cv::IMREAD_IGNORE_ORIENTATION);
      } catch (const cv::Exception&) {
        return false;
      }
      if (decoded.cols != width_px_ || decoded.rows != height_px_ || decoded.type() != CV_8UC1)
        return false;
      for (int y = 0; y < height_px_; ++y) {
        std::memcpy(dst + static_cast<std::size_t>(y) * width, decoded.ptr<uint8_t>(y), width);
      }
      break;
    }
    default:
      return false;
  }
  *out = ImageView{width_px_, height_px_, width, dst};
  return true;
}

void PixelFormatConverter::Mono16ToMono8(const uint8_t* src, std::size_t src_stride, int width_px,
                                         int height_px, int shift_bits, uint8_t* dst,
                                         std::size_t dst_stride) {
  const auto width = static_cast<std::size_t>(width_px);
  for (int y = 0; y < height_px; ++y) {
    const uint8_t* s = src + static_cast<std::size_t>(y) * src_stride;
    uint8_t* d = dst + static_cast<std::size_t>(y) * dst_stride;
    for (std::size_t x = 0; x < width; ++x) {
      // Little-endian per V4L2; assembled bytewise so rows need no alignment.
      const unsigned value =
          static_cast<unsigned>(s[2 * x]) | (static_cast<unsigned>(s[2 * x + 1]) << 8);
      d[x] = static_cast<uint8_t>(std::min(value >> shift_bits, 255u));
    }
  }
}

void PixelFormatConverter::YuyvToMono8(const uint8_t* src, std::size_t src_stride, int width_px,
                                       int height_px, uint8_t* dst, std::size_t dst_stride) {
  const auto width = static_cast<std::size_t>(width_px);
  for (int y = 0; y < height_px; ++y) {
    const uint8_t* s = src + static_cast<std::size_t>(y) * src_stride;
    uint8_t* d = dst + static_cast<std::size_t>(y) * dst_stride;
    for (std::size_t x = 0; x < width; ++x) d[x] = s[2 * x];
  }
}

}  // namespace rover::drivers
