#include "drivers/imu/mt_data2_packet.h"

#include <gtest/gtest.h>

#include <vector>

namespace rover::drivers {
namespace {

MtData2Packet FullPacket() {
  MtData2Packet p;
  p.has_packet_counter = p.has_sample_time_fine = p.has_acceleration = p.has_rate_of_turn = true;
  p.packet_counter = 0x1234;
  p.sample_time_fine = 0x00ABCDEF;
  p.acceleration_m_s2 = {1.0f, -2.5f, 9.81f};
  p.rate_of_turn_rad_s = {0.0f, 0.125f, -3.0f};
  return p;
}

TEST(MtData2PacketTest, EncodesItemsAsIdSizeAndBigEndianData) {
  MtData2Packet p;
  p.has_packet_counter = true;
  p.packet_counter = 0x1234;
  p.has_acceleration = true;
  p.acceleration_m_s2 = {1.0f, 0.0f, -2.0f};  // 0x3F800000, 0, 0xC0000000
  std::vector<uint8_t> out(64);
  ASSERT_EQ(EncodeMtData2(p, out), 5u + 15u);
  const std::vector<uint8_t> expected = {0x10, 0x20, 0x02, 0x12, 0x34,  // PacketCounter
                                         0x40, 0x20, 0x0C,              // Acceleration
                                         0x3F, 0x80, 0x00, 0x00, 0x00, 0x00,
                                         0x00, 0x00, 0xC0, 0x00, 0x00, 0x00};
  EXPECT_EQ(std::vector<uint8_t>(out.begin(), out.begin() + 20), expected);
}

TEST(MtData2PacketTest, RoundTripsACompletePacket) {
  const MtData2Packet p = FullPacket();
  std::vector<uint8_t> out(kMtData2CompletePayloadBytes);
  ASSERT_EQ(EncodeMtData2(p, out), kMtData2CompletePayloadBytes);
  MtData2Packet q;
  ASSERT_TRUE(DecodeMtData2(out, &q));
  EXPECT_TRUE(q.complete());
  EXPECT_EQ(q.packet_counter, p.packet_counter);
  EXPECT_EQ(q.sample_time_fine, p.sample_time_fine);
  EXPECT_EQ(q.acceleration_m_s2, p.acceleration_m_s2);
  EXPECT_EQ(q.rate_of_turn_rad_s, p.rate_of_turn_rad_s);
  std::vector<uint8_t> small(kMtData2CompletePayloadBytes - 1);
  EXPECT_EQ(EncodeMtData2(p, small), 0u);
}

TEST(MtData2PacketTest, SkipsItemsItDoesNotUse) {
  std::vector<uint8_t> payload = {0x20, 0x10, 0x10};  // Quaternion, 16 bytes
  payload.resize(payload.size() + 16, 0xAB);
  const std::vector<uint8_t> counter = {0x10, 0x20, 0x02, 0x00, 0x07};
  payload.insert(payload.end(), counter.begin(), counter.end());
  MtData2Packet p;
  ASSERT_TRUE(DecodeMtData2(payload, &p));
  EXPECT_TRUE(p.has_packet_counter);
  EXPECT_EQ(p.packet_counter, 7);
  EXPECT_FALSE(p.has_acceleration);
  EXPECT_FALSE(p.complete());
}

TEST(MtData2PacketTest, RejectsItemsRunningPastThePayloadOrWithWrongSizes) {
  MtData2Packet p;
  EXPECT_FALSE(DecodeMtData2(std::vector<uint8_t>{0x10, 0x20, 0x02, 0x00}, &p));     // cut short
  EXPECT_FALSE(DecodeMtData2(std::vector<uint8_t>{0x10, 0x20}, &p));                 // header cut
  EXPECT_FALSE(DecodeMtData2(std::vector<uint8_t>{0x10, 0x20, 0x03, 0, 0, 0}, &p));  // size 3
  std::vector<uint8_t> accel = {0x40, 0x20, 0x08};  // 8 bytes: not 3 floats
  accel.resize(11);
  EXPECT_FALSE(DecodeMtData2(accel, &p));
  EXPECT_TRUE(DecodeMtData2(std::vector<uint8_t>{}, &p));  // empty is valid, and empty
  EXPECT_FALSE(p.has_packet_counter);
}

}  // namespace
}  // namespace rover::drivers
