#include "drivers/imu/xbus_protocol.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <numeric>
#include <vector>

namespace rover::drivers {
namespace {

std::vector<uint8_t> Encode(uint8_t mid, const std::vector<uint8_t>& payload) {
  std::vector<uint8_t> out(xbus::FrameBytes(payload.size()));
  EXPECT_EQ(xbus::EncodeMessage(mid, payload, out), out.size());
  return out;
}

unsigned SumAfterPreamble(const std::vector<uint8_t>& frame) {
  return std::accumulate(frame.begin() + 1, frame.end(), 0u) & 0xFFu;
}

// The frames every Xsens driver sends first; the bytes are the ones the
// protocol document lists.
TEST(XbusProtocolTest, EncodesTheWellKnownConfigurationRequests) {
  EXPECT_EQ(Encode(xbus::mid::kGoToConfig, {}),
            (std::vector<uint8_t>{0xFA, 0xFF, 0x30, 0x00, 0xD1}));
  EXPECT_EQ(Encode(xbus::mid::kGoToMeasurement, {}),
            (std::vector<uint8_t>{0xFA, 0xFF, 0x10, 0x00, 0xF1}));
  EXPECT_EQ(Encode(xbus::mid::kReqDid, {}), (std::vector<uint8_t>{0xFA, 0xFF, 0x00, 0x00, 0x01}));
}

TEST(XbusProtocolTest, ChecksumMakesTheBytesAfterThePreambleSumToZero) {
  // SetOutputConfiguration with one item: 0xFF + 0xC0 + 0x04 + 0x40 + 0x20 +
  // 0x01 + 0x90 = 0x2B4; 0x100 - 0xB4 = 0x4C.
  const std::vector<uint8_t> frame =
      Encode(xbus::mid::kSetOutputConfiguration, {0x40, 0x20, 0x01, 0x90});
  EXPECT_EQ(frame.back(), 0x4C);
  EXPECT_EQ(SumAfterPreamble(frame), 0u);
}

TEST(XbusProtocolTest, UsesTheExtendedLengthFrom255Bytes) {
  for (const std::size_t size : {0u, 1u, 254u, 255u, 256u, 300u, 2048u}) {
    std::vector<uint8_t> payload(size);
    for (std::size_t i = 0; i < size; ++i) payload[i] = static_cast<uint8_t>(i * 7 + 3);
    const std::vector<uint8_t> frame = Encode(xbus::mid::kMtData2, payload);
    SCOPED_TRACE(size);
    EXPECT_EQ(frame[0], 0xFA);
    EXPECT_EQ(frame[1], 0xFF);
    EXPECT_EQ(frame[2], 0x36);
    if (size < 255) {
      EXPECT_EQ(frame.size(), size + 5);
      EXPECT_EQ(frame[3], size);
    } else {
      EXPECT_EQ(frame.size(), size + 7);
      EXPECT_EQ(frame[3], 0xFF);
      EXPECT_EQ(xbus::ReadU16(&frame[4]), size);
    }
    EXPECT_EQ(SumAfterPreamble(frame), 0u);
  }
}

TEST(XbusProtocolTest, RefusesOversizePayloadsAndSmallBuffers) {
  std::vector<uint8_t> payload(xbus::kMaxPayloadBytes + 1);
  std::vector<uint8_t> out(xbus::FrameBytes(payload.size()));
  EXPECT_EQ(xbus::EncodeMessage(xbus::mid::kMtData2, payload, out), 0u);
  std::vector<uint8_t> small(4);
  EXPECT_EQ(xbus::EncodeMessage(xbus::mid::kGoToConfig, {}, small), 0u);
}

TEST(XbusProtocolTest, BigEndianFieldsRoundTrip) {
  uint8_t b[4];
  xbus::WriteU16(0x1234, b);
  EXPECT_EQ(b[0], 0x12);
  EXPECT_EQ(b[1], 0x34);
  EXPECT_EQ(xbus::ReadU16(b), 0x1234);
  xbus::WriteU32(0xDEADBEEF, b);
  EXPECT_EQ(b[0], 0xDE);
  EXPECT_EQ(b[3], 0xEF);
  EXPECT_EQ(xbus::ReadU32(b), 0xDEADBEEFu);
  xbus::WriteF32(1.0f, b);  // IEEE 754: 0x3F800000
  EXPECT_EQ(xbus::ReadU32(b), 0x3F800000u);
  xbus::WriteF32(-9.81f, b);
  EXPECT_EQ(xbus::ReadF32(b), -9.81f);
}

TEST(XbusProtocolTest, NamesTheErrorCodes) {
  EXPECT_STREQ(xbus::ErrorCodeName(0x03), "invalid period");
  EXPECT_STREQ(xbus::ErrorCodeName(0x04), "invalid or unsupported message");
  EXPECT_STREQ(xbus::ErrorCodeName(0x99), "unknown error");
}

}  // namespace
}  // namespace rover::drivers
