// Images in the flight log: thumbnails are block means at the configured
// rate, full frames are the captured rows, and the camera thread's call
// neither allocates nor blocks.

#include "firmware/roverd/image_logger.h"

#include <gtest/gtest.h>

#include <vector>

#include "core/log/mcap/mcap_reader.h"
#include "core/log/msgs/message_traits.h"
#include "tests/support/allocation_counter.h"
#include "tests/support/malloc_counter.h"
#include "tests/support/temp_dir.h"

namespace rover::roverd {
namespace {

using log::sensor_msgs::Image;

std::vector<std::pair<std::string, Image>> ReadImages(const std::string& path) {
  log::McapReader reader = log::McapReader::Open(path);
  std::vector<std::pair<std::string, Image>> out;
  reader.ForEachMessage([&](const log::MessageView& m) {
    const std::string& topic = reader.channels().at(m.channel_id).topic;
    if (topic.rfind("/camera/", 0) != 0) return true;
    Image image;
    EXPECT_TRUE(log::DeserializeMessage(m.data, &image));
    out.emplace_back(topic, std::move(image));
    return true;
  });
  return out;
}

struct Pixels {
  Pixels(int w, int h, std::size_t stride) : width(w), height(h), stride_bytes(stride) {
    data.resize(stride * static_cast<std::size_t>(h));
    for (int r = 0; r < h; ++r) {
      for (int c = 0; c < w; ++c)
        data[static_cast<std::size_t>(r) * stride + static_cast<std::size_t>(c)] = Value(r, c);
    }
  }
  static uint8_t Value(int r, int c) { return static_cast<uint8_t>((r * 7 + c * 3) % 251); }
  drivers::ImageView View() const { return {width, height, stride_bytes, data.data()}; }
  int width, height;
  std::size_t stride_bytes;
  std::vector<uint8_t> data;
};

TEST(ImageLoggerTest, ThumbnailsAreBlockMeansAtTheConfiguredRate) {
  const rover::testing::TempDir dir;
  const std::string path = (dir.path() / "t.mcap").string();
  const Pixels left(752, 480, 768);
  {
    log::FlightLog flight_log;
    flight_log.Open(path);
    ImageLogger logger(
        {.mode = ImageLogMode::kThumbnails, .thumbnail_width_px = 188, .thumbnail_rate_hz = 2.0},
        &flight_log);
    flight_log.Start();
    drivers::StereoFrame frame;
    frame.cam0 = left.View();
    for (int i = 0; i < 20; ++i) {  // 10 Hz for 2 s: a thumbnail every 0.5 s
      frame.stamp = Time::FromSeconds(10.0 + 0.1 * i);
      logger.OnFrame(frame);
    }
    flight_log.Stop();
    EXPECT_EQ(logger.logged(), 4u);
  }
  const auto images = ReadImages(path);
  ASSERT_EQ(images.size(), 4u);
  const Image& t = images[0].second;
  EXPECT_EQ(images[0].first, "/camera/cam0/thumbnail");
  EXPECT_EQ(t.width, 188u);  // factor 4
  EXPECT_EQ(t.height, 120u);
  EXPECT_EQ(t.encoding, "mono8");
  for (int r : {0, 57, 119}) {
    for (int c : {0, 100, 187}) {
      int sum = 0;
      for (int dr = 0; dr < 4; ++dr) {
        for (int dc = 0; dc < 4; ++dc) sum += Pixels::Value(4 * r + dr, 4 * c + dc);
      }
      EXPECT_EQ(t.data[static_cast<std::size_t>(r * 188 + c)], (sum + 8) / 16) << r << "," << c;
    }
  }
}

TEST(ImageLoggerTest, FullModeLogsBothImagesRowForRowWithoutAllocating) {
  const rover::testing::TempDir dir;
  const std::string path = (dir.path() / "f.mcap").string();
  const Pixels left(64, 48, 80), right(64, 48, 64);
  {
    log::FlightLog flight_log;
    flight_log.Open(path);
    ImageLogger logger({.mode = ImageLogMode::kFull}, &flight_log);
    flight_log.Start();
    drivers::StereoFrame frame;
    frame.cam0 = left.View();
    frame.cam1 = right.View();
    frame.stamp = Time::FromSeconds(1.0);
    logger.OnFrame(frame);
    rover::testing::ScopedAllocationCheck news;
    rover::testing::ScopedMallocCheck mallocs;
    frame.stamp = Time::FromSeconds(1.1);
    logger.OnFrame(frame);
    EXPECT_EQ(news.allocations(), 0u);
    EXPECT_EQ(mallocs.mallocs(), 0u);
    flight_log.Stop();
  }
  const auto images = ReadImages(path);
  ASSERT_EQ(images.size(), 4u);
  int cam1 = 0;
  for (const auto& [topic, image] : images) {
    ASSERT_EQ(image.width, 64u);
    ASSERT_EQ(image.data.size(), 64u * 48u);
    if (topic == "/camera/cam1/image_raw") ++cam1;
    for (int r = 0; r < 48; ++r) {
      ASSERT_EQ(image.data[static_cast<std::size_t>(r * 64 + 63)], Pixels::Value(r, 63));
    }
  }
  EXPECT_EQ(cam1, 2);
}

TEST(ImageLoggerTest, RejectsBadOptions) {
  EXPECT_THROW(ParseImageLogMode("some"), std::invalid_argument);
  EXPECT_THROW((ImageLogOptions{.thumbnail_width_px = 8}).Validate(), std::invalid_argument);
  EXPECT_THROW((ImageLogOptions{.thumbnail_rate_hz = 0.0}).Validate(), std::invalid_argument);
}

}  // namespace
}  // namespace rover::roverd
