#include "drivers/can/wheel_speed_decoder.h"

#include <gtest/gtest.h>

#include <vector>

#include "drivers/can/canopen_wheel_protocol.h"

namespace rover::drivers {
namespace {

Time Ms(int64_t ms) { return Time::FromNanoseconds(1'000'000'000 + ms * 1'000'000); }

CanFrame Tpdo(int64_t ms, uint8_t node, int32_t velocity_mrad_s) {
  return EncodeWheelTpdo1(Ms(ms), {node, velocity_mrad_s, 0});
}

TEST(WheelSpeedDecoderTest, CompletePeriodIsStampedWithItsSync) {
  WheelSpeedDecoder d;
  EXPECT_FALSE(d.Feed(EncodeSync(Ms(10))));
  EXPECT_FALSE(d.Feed(Tpdo(11, 2, 2000)));
  EXPECT_FALSE(d.Feed(Tpdo(11, 1, 1000)));
  EXPECT_FALSE(d.Feed(Tpdo(12, 4, -4000)));
  const auto s = d.Feed(Tpdo(12, 3, 3000));
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->stamp, Ms(10));
  EXPECT_DOUBLE_EQ(s->wheel_rate_rad_s[0], 1.0);
  EXPECT_DOUBLE_EQ(s->wheel_rate_rad_s[1], 2.0);
  EXPECT_DOUBLE_EQ(s->wheel_rate_rad_s[2], 3.0);
  EXPECT_DOUBLE_EQ(s->wheel_rate_rad_s[3], -4.0);
  EXPECT_EQ(d.stats().complete, 1u);
}

TEST(WheelSpeedDecoderTest, PeriodWithAMissingDriveEmitsNothingAndIsCounted) {
  WheelSpeedDecoder d;
  d.Feed(EncodeSync(Ms(0)));
  for (uint8_t node = 1; node <= 3; ++node) EXPECT_FALSE(d.Feed(Tpdo(1, node, 500)));
  d.Feed(EncodeSync(Ms(10)));  // closes the period without drive 4
  EXPECT_EQ(d.stats().incomplete, 1u);
  EXPECT_EQ(d.stats().complete, 0u);
  // Late TPDO1 of the old period lands in the new one, which is still
  // missing the others: no emission from mixed periods.
  EXPECT_FALSE(d.Feed(Tpdo(11, 4, 500)));
}

TEST(WheelSpeedDecoderTest, TpdoBeforeAnySyncAndJunkAreIgnored) {
  WheelSpeedDecoder d;
  EXPECT_FALSE(d.Feed(Tpdo(0, 1, 100)));
  CanFrame junk;
  junk.id = 0x123;
  junk.dlc = 3;
  EXPECT_FALSE(d.Feed(junk));
  EXPECT_EQ(d.stats().ignored, 2u);
}

TEST(WheelSpeedDecoderTest, DriveWithoutHeartbeatIsReportedMissing) {
  WheelSpeedDecoder d(Duration::Milliseconds(2500));
  EXPECT_EQ(d.MissingDrives(Ms(0)), 0b1111);
  for (uint8_t node = 1; node <= 4; ++node)
    d.Feed(EncodeHeartbeat(Ms(100), {node, kNmtOperational}));
  EXPECT_EQ(d.MissingDrives(Ms(1000)), 0);
  for (uint8_t node = 1; node <= 3; ++node)
    d.Feed(EncodeHeartbeat(Ms(1100), {node, kNmtOperational}));
  EXPECT_EQ(d.MissingDrives(Ms(2700)), 0b1000);  // drive 4 silent for 2.6 s
  EXPECT_EQ(d.stats().heartbeats, 7u);
}

TEST(DecodeWheelSpeedsTest, NeedsAllFourDrivesAndIgnoresHeartbeats) {
  const Time t = Time::FromSeconds(10.0);
  std::vector<CanFrame> frames;
  frames.push_back(EncodeSync(t));
  for (uint8_t node = 1; node <= 4; ++node) {
    frames.push_back(
        EncodeWheelTpdo1(t + Duration::Microseconds(200 * node), {node, 1000 * node - 2500, 7}));
  }
  frames.push_back(EncodeHeartbeat(t + Duration::Milliseconds(2), {2, kNmtOperational}));
  const Time t2 = t + Duration::Milliseconds(10);
  frames.push_back(EncodeSync(t2));
  frames.push_back(EncodeWheelTpdo1(t2 + Duration::Microseconds(200), {1, 5, 0}));
  const auto out = DecodeWheelSpeeds(frames);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].stamp, t);
  EXPECT_DOUBLE_EQ(out[0].wheel_rate_rad_s[0], -1.5);
  EXPECT_DOUBLE_EQ(out[0].wheel_rate_rad_s[1], -0.5);
  EXPECT_DOUBLE_EQ(out[0].wheel_rate_rad_s[2], 0.5);
  EXPECT_DOUBLE_EQ(out[0].wheel_rate_rad_s[3], 1.5);
}

}  // namespace
}  // namespace rover::drivers
