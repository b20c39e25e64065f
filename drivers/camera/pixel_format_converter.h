#ifndef ROVER_DRIVERS_CAMERA_PIXEL_FORMAT_CONVERTER_H_
#define ROVER_DRIVERS_CAMERA_PIXEL_FORMAT_CONVERTER_H_

// Turns the content of one V4L2 capture buffer into the 8-bit mono
// ImageView the rest of the stack works on:
//  - GREY: the view points into the capture buffer itself (zero copy);
//  - Y10, Y12, Y16 (little-endian 16-bit containers): the 8 most significant
//    bits of each pixel (value >> 2, >> 4, >> 8) into a preallocated image;
//  - YUYV: the luma bytes (every second byte) into a preallocated image;
//  - MJPG: decoded to grey with OpenCV, then copied into a preallocated
//    image.
//
// One output image per capture buffer is allocated at construction, so a
// frame's view stays valid for as long as the caller holds its buffer, and
// several frames may be held at once.
//
// Real time: Convert() never allocates for the uncompressed formats. MJPG is
// NOT real-time safe: cv::imdecode creates a decoder and its work buffers on
// every call (malloc), and its run time depends on the compressed content.
// real_time_safe() says which case applies.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "drivers/camera/stereo_frame.h"

namespace rover::drivers {

/// The four characters of a V4L2 fourcc, trailing blanks removed ("GREY",
/// "Y16", "YUYV", "MJPG"); non-printable bytes as '?'.
std::string FourccToString(uint32_t fourcc);

/// The fourcc of a text such as "GREY" or "Y16" (1 to 4 printable
/// characters, padded with blanks as V4L2 does). Throws
/// std::invalid_argument for an empty, longer or non-printable text.
uint32_t FourccFromString(const std::string& text);

class PixelFormatConverter {
 public:
  /// True for the formats this class converts: GREY, Y10, Y12, Y16, YUYV,
  /// MJPG.
  static bool Supports(uint32_t fourcc);

  /// Prepares the conversion of `fourcc` images of `width_px` x `height_px`
  /// whose rows are `bytes_per_line` apart in the capture buffer (ignored
  /// for MJPG), into `slots` output images (one per capture buffer),
  /// allocated here. Throws std::invalid_argument for an unsupported
  /// format, a size below 1x1 or above 16384x16384, a stride shorter than a
  /// row, or `slots` outside [1, 32].
  PixelFormatConverter(uint32_t fourcc, int width_px, int height_px, std::size_t bytes_per_line,
                       int slots);

  /// Converts the `bytes_used` bytes at `data`, the content of capture
  /// buffer `slot`, into *out. GREY: *out points into `data`; otherwise into
  /// the slot's own image (overwritten by the next Convert() of that slot).
  /// Returns false, leaving *out unchanged, when `slot` is out of range,
  /// the buffer is shorter than one uncompressed frame (min_frame_bytes()),
  /// or an MJPG buffer does not decode to an image of the configured size.
  /// Never allocates except for MJPG (see the file comment).
  bool Convert(const uint8_t* data, std::size_t bytes_used, int slot, ImageView* out);

  /// Bytes a complete uncompressed frame occupies in a capture buffer:
  /// bytes_per_line * (height - 1) + the bytes of one row; 1 for MJPG (any
  /// non-empty buffer may decode).
  std::size_t min_frame_bytes() const { return min_frame_bytes_; }
  /// False for MJPG (cv::imdecode allocates), true otherwise.
  bool real_time_safe() const;
  /// True for GREY: the view points into the capture buffer.
  bool zero_copy() const;
  uint32_t fourcc() const { return fourcc_; }
  int width_px() const { return width_px_; }
  int height_px() const { return height_px_; }

  // The conversion kernels, for tests and benchmarks. `src_stride` and
  // `dst_stride` are the byte distances between rows.

  /// 16-bit little-endian pixels to 8 bits: dst = src >> shift_bits, with
  /// shift_bits in [0, 8] (8 for Y16, 4 for Y12, 2 for Y10); values above
  /// the format's range saturate at 255.
  static void Mono16ToMono8(const uint8_t* src, std::size_t src_stride, int width_px, int height_px,
                            int shift_bits, uint8_t* dst, std::size_t dst_stride);
  /// YUYV 4:2:2 (Y0 U Y1 V per pixel pair) to its luma plane.
  static void YuyvToMono8(const uint8_t* src, std::size_t src_stride, int width_px, int height_px,
                          uint8_t* dst, std::size_t dst_stride);

 private:
  uint32_t fourcc_ = 0;
  int width_px_ = 0;
  int height_px_ = 0;
  std::size_t bytes_per_line_ = 0;
  std::size_t min_frame_bytes_ = 0;
  /// One width x height image per slot (empty for GREY).
  std::vector<std::vector<uint8_t>> images_{};
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_CAMERA_PIXEL_FORMAT_CONVERTER_H_
