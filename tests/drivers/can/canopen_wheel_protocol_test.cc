#include "drivers/can/canopen_wheel_protocol.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <limits>

namespace rover::drivers {
namespace {

const Time kStamp = Time::FromNanoseconds(123'456'789);

TEST(CanopenWheelProtocolTest, Tpdo1LayoutIsLittleEndianVelocityThenPosition) {
  const CanFrame f = EncodeWheelTpdo1(kStamp, {3, 0x01020304, static_cast<int32_t>(0xF1F2F3F4u)});
  EXPECT_EQ(f.stamp, kStamp);
  EXPECT_EQ(f.id, 0x183u);
  EXPECT_EQ(f.dlc, 8);
  const std::array<uint8_t, 8> expected{0x04, 0x03, 0x02, 0x01, 0xF4, 0xF3, 0xF2, 0xF1};
  EXPECT_EQ(f.data, expected);
}

TEST(CanopenWheelProtocolTest, Tpdo1RoundTrip) {
  for (uint8_t node = 1; node <= 4; ++node) {
    for (const int32_t v : {0, 1, -1, 12345, -987654, std::numeric_limits<int32_t>::max(),
                            std::numeric_limits<int32_t>::min()}) {
      const WheelTpdo1 in{node, v, -v / 3 + 7};
      const auto out = DecodeWheelTpdo1(EncodeWheelTpdo1(kStamp, in));
      ASSERT_TRUE(out.has_value());
      EXPECT_EQ(out->node_id, node);
      EXPECT_EQ(out->velocity_mrad_s, in.velocity_mrad_s);
      EXPECT_EQ(out->position_ticks, in.position_ticks);
    }
  }
}

TEST(CanopenWheelProtocolTest, DecodersRejectOtherFrames) {
  CanFrame f = EncodeWheelTpdo1(kStamp, {1, 5, 6});
  f.dlc = 7;
  EXPECT_FALSE(DecodeWheelTpdo1(f).has_value());
  f = EncodeWheelTpdo1(kStamp, {1, 5, 6});
  f.id = 0x185;  // node 5 is not a wheel drive
  EXPECT_FALSE(DecodeWheelTpdo1(f).has_value());
  f.id = 0x180;
  EXPECT_FALSE(DecodeWheelTpdo1(f).has_value());
  EXPECT_FALSE(DecodeWheelTpdo1(EncodeSync(kStamp)).has_value());
  EXPECT_FALSE(DecodeHeartbeat(EncodeSync(kStamp)).has_value());
  EXPECT_FALSE(IsSync(EncodeHeartbeat(kStamp, {1, kNmtOperational})));
}

TEST(CanopenWheelProtocolTest, SyncAndHeartbeat) {
  const CanFrame sync = EncodeSync(kStamp);
  EXPECT_EQ(sync.id, 0x080u);
  EXPECT_EQ(sync.dlc, 0);
  EXPECT_TRUE(IsSync(sync));
  const CanFrame beat = EncodeHeartbeat(kStamp, {4, kNmtOperational});
  EXPECT_EQ(beat.id, 0x704u);
  EXPECT_EQ(beat.dlc, 1);
  EXPECT_EQ(beat.data[0], 0x05);
  const auto decoded = DecodeHeartbeat(beat);
  ASSERT_TRUE(decoded.has_value());
  EXPECT_EQ(decoded->node_id, 4);
  EXPECT_EQ(decoded->nmt_state, kNmtOperational);
}

TEST(CanopenWheelProtocolTest, VelocityUnitsAndTickWrap) {
  EXPECT_EQ(VelocityToTpdo(1.2345), 1235);
  EXPECT_EQ(VelocityToTpdo(-0.0004), 0);
  EXPECT_EQ(VelocityToTpdo(-3.0), -3000);
  EXPECT_EQ(VelocityToTpdo(1e12), std::numeric_limits<int32_t>::max());
  EXPECT_EQ(VelocityToTpdo(-1e12), std::numeric_limits<int32_t>::min());
  EXPECT_EQ(WrapTicks(5), 5);
  EXPECT_EQ(WrapTicks(-5), -5);
  EXPECT_EQ(WrapTicks(int64_t{1} << 31), std::numeric_limits<int32_t>::min());
  EXPECT_EQ(WrapTicks((int64_t{1} << 32) + 17), 17);
  // Differences of wrapped positions stay right across the wrap.
  const int64_t a = (int64_t{1} << 31) - 100, b = a + 250;
  EXPECT_EQ(static_cast<int32_t>(static_cast<uint32_t>(WrapTicks(b)) -
                                 static_cast<uint32_t>(WrapTicks(a))),
            250);
}

}  // namespace
}  // namespace rover::drivers
