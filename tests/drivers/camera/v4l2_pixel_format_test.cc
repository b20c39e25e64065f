// PixelFormatConverter against hand-made capture buffers: every supported
// V4L2 format, padded rows, short buffers, per-buffer output images, and
// MJPG through a JPEG made by OpenCV. Built twice: the behaviour tests
// (under the sanitizers) and, with ROVER_TEST_MALLOC_COUNTER, the proof
// that converting the uncompressed formats never allocates.

#include <linux/videodev2.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <stdexcept>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "drivers/camera/pixel_format_converter.h"

#ifdef ROVER_TEST_MALLOC_COUNTER
#include "tests/support/malloc_counter.h"
#endif

namespace rover::drivers {
namespace {

using ::testing::HasSubstr;

uint8_t At(const ImageView& v, int x, int y) {
  return v.data[static_cast<std::size_t>(y) * v.stride_bytes + static_cast<std::size_t>(x)];
}

#ifndef ROVER_TEST_MALLOC_COUNTER

/// The 8-bit value the tests put at (x, y).
uint8_t Pattern(int x, int y) { return static_cast<uint8_t>((x * 7 + y * 13) & 0xFF); }

/// A capture buffer of `bytes_per_line` x height, padding filled with 0xEE
/// so a converter that reads it shows.
std::vector<uint8_t> Buffer(std::size_t bytes_per_line, int height) {
  return std::vector<uint8_t>(bytes_per_line * static_cast<std::size_t>(height), 0xEE);
}

TEST(FourccTest, RoundTripsTextAndCode) {
  EXPECT_EQ(FourccFromString("GREY"), V4L2_PIX_FMT_GREY);
  EXPECT_EQ(FourccFromString("Y16"), V4L2_PIX_FMT_Y16);
  EXPECT_EQ(FourccFromString("YUYV"), V4L2_PIX_FMT_YUYV);
  EXPECT_EQ(FourccFromString("MJPG"), V4L2_PIX_FMT_MJPEG);
  EXPECT_EQ(FourccToString(V4L2_PIX_FMT_Y16), "Y16");
  EXPECT_EQ(FourccToString(V4L2_PIX_FMT_Y10), "Y10");
  EXPECT_EQ(FourccToString(V4L2_PIX_FMT_Y16_BE), "Y16-BE");
  EXPECT_EQ(FourccToString(V4L2_PIX_FMT_MJPEG), "MJPG");
  EXPECT_THROW(FourccFromString(""), std::invalid_argument);
  EXPECT_THROW(FourccFromString("GREYY"), std::invalid_argument);
}

TEST(PixelFormatConverterTest, SupportsTheMonoFormatsOnly) {
  for (const uint32_t f : {V4L2_PIX_FMT_GREY, V4L2_PIX_FMT_Y10, V4L2_PIX_FMT_Y12, V4L2_PIX_FMT_Y16,
                           V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_MJPEG}) {
    EXPECT_TRUE(PixelFormatConverter::Supports(f)) << FourccToString(f);
  }
  EXPECT_FALSE(PixelFormatConverter::Supports(V4L2_PIX_FMT_UYVY));
  EXPECT_FALSE(PixelFormatConverter::Supports(V4L2_PIX_FMT_RGB24));
  try {
    PixelFormatConverter converter(V4L2_PIX_FMT_UYVY, 8, 4, 16, 2);
    FAIL() << "UYVY accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("UYVY"));
    EXPECT_THAT(e.what(), HasSubstr("GREY"));
  }
}

TEST(PixelFormatConverterTest, RejectsInconsistentGeometry) {
  EXPECT_THROW(PixelFormatConverter(V4L2_PIX_FMT_YUYV, 8, 4, 15, 2),
               std::invalid_argument);  // stride < row
  EXPECT_THROW(PixelFormatConverter(V4L2_PIX_FMT_GREY, 0, 4, 8, 2), std::invalid_argument);
  EXPECT_THROW(PixelFormatConverter(V4L2_PIX_FMT_GREY, 8, 4, 8, 0), std::invalid_argument);
  EXPECT_THROW(PixelFormatConverter(V4L2_PIX_FMT_GREY, 8, 4, 8, 33), std::invalid_argument);
}

TEST(PixelFormatConverterTest, GreyIsZeroCopyWithTheDriversStride) {
  constexpr int kW = 10, kH = 6;
  constexpr std::size_t kStride = 16;  // padded rows
  std::vector<uint8_t> buffer = Buffer(kStride, kH);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x)
      buffer[static_cast<std::size_t>(y) * kStride + static_cast<std::size_t>(x)] = Pattern(x, y);
  }
  PixelFormatConverter converter(V4L2_PIX_FMT_GREY, kW, kH, kStride, 4);
  EXPECT_TRUE(converter.zero_copy());
  EXPECT_TRUE(converter.real_time_safe());
  EXPECT_EQ(converter.min_frame_bytes(), kStride * (kH - 1) + kW);
  ImageView view;
  ASSERT_TRUE(converter.Convert(buffer.data(), buffer.size(), 3, &view));
  EXPECT_EQ(view.data, buffer.data());
  EXPECT_EQ(view.stride_bytes, kStride);
  EXPECT_EQ(view.width_px, kW);
  EXPECT_EQ(view.height_px, kH);
  EXPECT_EQ(At(view, 9, 5), Pattern(9, 5));
  // The last row needs no padding after it.
  ASSERT_TRUE(converter.Convert(buffer.data(), kStride * (kH - 1) + kW, 0, &view));
}

TEST(PixelFormatConverterTest, ShortBufferAndBadSlotAreRefused) {
  std::vector<uint8_t> buffer = Buffer(16, 4);
  PixelFormatConverter converter(V4L2_PIX_FMT_YUYV, 8, 4, 16, 2);
  ImageView view;
  view.width_px = -7;
  EXPECT_FALSE(converter.Convert(buffer.data(), buffer.size() - 1, 0, &view));
  EXPECT_FALSE(converter.Convert(buffer.data(), buffer.size(), 2, &view));
  EXPECT_FALSE(converter.Convert(buffer.data(), buffer.size(), -1, &view));
  EXPECT_FALSE(converter.Convert(nullptr, buffer.size(), 0, &view));
  EXPECT_EQ(view.width_px, -7) << "a refused buffer must leave the view alone";
  EXPECT_TRUE(converter.Convert(buffer.data(), buffer.size(), 1, &view));
}

TEST(PixelFormatConverterTest, Y16GivesTheHighByte) {
  constexpr int kW = 6, kH = 3;
  constexpr std::size_t kStride = 16;  // 12 bytes of pixels + 4 padding
  std::vector<uint8_t> buffer = Buffer(kStride, kH);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      // Little endian: low byte first. The low byte must not leak in.
      const std::size_t i = static_cast<std::size_t>(y) * kStride + 2 * static_cast<std::size_t>(x);
      buffer[i] = static_cast<uint8_t>(0xFF - Pattern(x, y));
      buffer[i + 1] = Pattern(x, y);
    }
  }
  PixelFormatConverter converter(V4L2_PIX_FMT_Y16, kW, kH, kStride, 2);
  EXPECT_FALSE(converter.zero_copy());
  ImageView view;
  ASSERT_TRUE(converter.Convert(buffer.data(), buffer.size(), 1, &view));
  EXPECT_EQ(view.stride_bytes, static_cast<std::size_t>(kW));
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) EXPECT_EQ(At(view, x, y), Pattern(x, y)) << x << "," << y;
  }
}

TEST(PixelFormatConverterTest, Y10AndY12KeepTheirEightMostSignificantBits) {
  // LSB-aligned containers: 10-bit 0x3FF -> 255, 0x200 -> 128; 12-bit 0xABC -> 0xAB.
  const std::vector<uint8_t> y10 = {0xFF, 0x03, 0x00, 0x02, 0x04, 0x00, 0xFF, 0xFF};
  PixelFormatConverter c10(V4L2_PIX_FMT_Y10, 4, 1, 8, 1);
  ImageView view;
  ASSERT_TRUE(c10.Convert(y10.data(), y10.size(), 0, &view));
  EXPECT_EQ(At(view, 0, 0), 255);
  EXPECT_EQ(At(view, 1, 0), 128);
  EXPECT_EQ(At(view, 2, 0), 1);
  EXPECT_EQ(At(view, 3, 0), 255) << "bits above the format's range saturate";
  const std::vector<uint8_t> y12 = {0xBC, 0x0A, 0x0F, 0x00};
  PixelFormatConverter c12(V4L2_PIX_FMT_Y12, 2, 1, 4, 1);
  ASSERT_TRUE(c12.Convert(y12.data(), y12.size(), 0, &view));
  EXPECT_EQ(At(view, 0, 0), 0xAB);
  EXPECT_EQ(At(view, 1, 0), 0);
}

TEST(PixelFormatConverterTest, YuyvGivesTheLumaPlane) {
  constexpr int kW = 8, kH = 3;
  constexpr std::size_t kStride = 20;
  std::vector<uint8_t> buffer = Buffer(kStride, kH);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * kStride + 2 * static_cast<std::size_t>(x);
      buffer[i] = Pattern(x, y);                                       // Y
      buffer[i + 1] = static_cast<uint8_t>(x % 2 == 0 ? 0x11 : 0x99);  // U / V
    }
  }
  PixelFormatConverter converter(V4L2_PIX_FMT_YUYV, kW, kH, kStride, 3);
  ImageView view;
  ASSERT_TRUE(converter.Convert(buffer.data(), buffer.size(), 2, &view));
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) EXPECT_EQ(At(view, x, y), Pattern(x, y)) << x << "," << y;
  }
}

TEST(PixelFormatConverterTest, EachBufferHasItsOwnImage) {
  std::vector<uint8_t> a(16, 0), b(16, 0);
  for (std::size_t i = 0; i < 16; i += 2) {
    a[i] = 10;
    b[i] = 200;
  }
  PixelFormatConverter converter(V4L2_PIX_FMT_YUYV, 4, 2, 8, 2);
  ImageView va, vb;
  ASSERT_TRUE(converter.Convert(a.data(), a.size(), 0, &va));
  ASSERT_TRUE(converter.Convert(b.data(), b.size(), 1, &vb));
  EXPECT_NE(va.data, vb.data);
  EXPECT_EQ(At(va, 3, 1), 10) << "converting buffer 1 overwrote the image of buffer 0";
  EXPECT_EQ(At(vb, 3, 1), 200);
}

TEST(PixelFormatConverterTest, MjpgDecodesToGrey) {
  constexpr int kW = 64, kH = 48;
  cv::Mat image(kH, kW, CV_8UC1);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x)
      image.at<uint8_t>(y, x) = static_cast<uint8_t>(x * 4);  // smooth ramp
  }
  std::vector<uint8_t> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", image, jpeg, {cv::IMWRITE_JPEG_QUALITY, 100}));
  PixelFormatConverter converter(V4L2_PIX_FMT_MJPEG, kW, kH, 0, 2);
  EXPECT_FALSE(converter.real_time_safe());
  ImageView view;
  ASSERT_TRUE(converter.Convert(jpeg.data(), jpeg.size(), 1, &view));
  EXPECT_EQ(view.width_px, kW);
  EXPECT_EQ(view.stride_bytes, static_cast<std::size_t>(kW));
  for (int y = 0; y < kH; y += 7) {
    for (int x = 0; x < kW; x += 5) EXPECT_NEAR(At(view, x, y), x * 4, 3) << x << "," << y;
  }
}

TEST(PixelFormatConverterTest, MjpgOfAnotherSizeOrGarbageIsRefused) {
  cv::Mat other(20, 30, CV_8UC1, cv::Scalar(77));
  std::vector<uint8_t> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", other, jpeg));
  PixelFormatConverter converter(V4L2_PIX_FMT_MJPEG, 64, 48, 0, 1);
  ImageView view;
  EXPECT_FALSE(converter.Convert(jpeg.data(), jpeg.size(), 0, &view));
  const std::vector<uint8_t> garbage(500, 0x5A);
  EXPECT_FALSE(converter.Convert(garbage.data(), garbage.size(), 0, &view));
  EXPECT_FALSE(converter.Convert(garbage.data(), 0, 0, &view)) << "an empty buffer";
}

#else  // ROVER_TEST_MALLOC_COUNTER

TEST(PixelFormatConverterAllocationTest, UncompressedFormatsConvertWithoutAllocating) {
  constexpr int kW = 64, kH = 32;
  const std::vector<uint8_t> buffer(static_cast<std::size_t>(kW) * 2 * kH, 0x42);
  std::vector<PixelFormatConverter> converters;
  for (const uint32_t f : {V4L2_PIX_FMT_GREY, V4L2_PIX_FMT_Y10, V4L2_PIX_FMT_Y12, V4L2_PIX_FMT_Y16,
                           V4L2_PIX_FMT_YUYV}) {
    const std::size_t stride = f == V4L2_PIX_FMT_GREY ? kW : 2 * kW;
    converters.emplace_back(f, kW, kH, stride, 4);
  }
  ImageView view;
  uint64_t sum = 0;
  const rover::testing::ScopedMallocCheck check;
  for (int round = 0; round < 50; ++round) {
    for (PixelFormatConverter& c : converters) {
      ASSERT_TRUE(c.Convert(buffer.data(), buffer.size(), round % 4, &view));
      sum += At(view, kW - 1, kH - 1);
    }
  }
  EXPECT_EQ(check.mallocs(), 0u);
  EXPECT_GT(sum, 0u);
}

#endif  // ROVER_TEST_MALLOC_COUNTER

}  // namespace
}  // namespace rover::drivers
