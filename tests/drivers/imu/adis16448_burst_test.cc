#include "drivers/imu/adis16448_burst.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "drivers/imu/adis16448_driver.h"
#include "drivers/imu/adis16448_registers.h"

namespace rover::drivers {
namespace {

// The burst of Analog Devices' CRC example (XGYRO_OUT..TEMP_OUT, given there
// low byte first: 15 0 248 255 10 0 65 254 204 255 86 4 39 2 163 253 18 244
// 60 193 108 255), whose CRC word is 0x9AF4.
Adis16448Burst ReferenceBurst() {
  Adis16448Burst b;
  b.diag_stat = 0x0000;
  b.gyro = {15, -8, 10};        // 0x000F, 0xFFF8, 0x000A
  b.accel = {-447, -52, 1110};  // 0xFE41, 0xFFCC, 0x0456
  b.mag = {551, -605, -3054};   // 0x0227, 0xFDA3, 0xF412
  b.baro = 0xC13C;              // 49468
  b.temp = 0xFF6C;
  return b;
}

TEST(Adis16448BurstTest, CrcMatchesTheReferenceExample) {
  EXPECT_EQ(ReferenceBurst().ComputeCrc(), 0x9AF4);
}

TEST(Adis16448BurstTest, CrcIgnoresDiagStatAndSeesEveryOtherWord) {
  Adis16448Burst b = ReferenceBurst();
  const uint16_t crc = b.ComputeCrc();
  b.diag_stat = 0x0008;
  EXPECT_EQ(b.ComputeCrc(), crc);
  b.temp ^= 0x0001;
  EXPECT_NE(b.ComputeCrc(), crc);
  b = ReferenceBurst();
  b.gyro[0] = 16;
  EXPECT_NE(b.ComputeCrc(), crc);
}

TEST(Adis16448BurstTest, ConvertsToSiUnits) {
  Adis16448Burst b;
  b.gyro = {25, -25, -32768};  // 1 deg/s, -1 deg/s, -1310.72 deg/s
  b.accel = {1200, 0, -1};     // 1200 * 0.833 mg = 0.9996 g
  ImuSample s;
  b.ToSample(&s);
  const double deg = std::numbers::pi / 180.0;
  EXPECT_NEAR(s.angular_velocity_rad_s.x(), 1.0 * deg, 1e-12);
  EXPECT_NEAR(s.angular_velocity_rad_s.y(), -1.0 * deg, 1e-12);
  EXPECT_NEAR(s.angular_velocity_rad_s.z(), -1310.72 * deg, 1e-9);
  EXPECT_NEAR(s.linear_acceleration_m_s2.x(), 0.9996 * 9.80665, 1e-9);
  EXPECT_NEAR(s.linear_acceleration_m_s2.y(), 0.0, 1e-15);
  EXPECT_NEAR(s.linear_acceleration_m_s2.z(), -0.833e-3 * 9.80665, 1e-12);

  const Adis16448Burst r = ReferenceBurst();
  // TEMP_OUT 0xFF6C: 12-bit 0xF6C = -148 -> 31 - 148 * 0.07386 = 20.06872 degC.
  EXPECT_NEAR(r.temperature_c(), 20.06872, 1e-9);
  Adis16448Burst warm;
  warm.temp = 0x0064;  // +100 -> 38.386 degC
  EXPECT_NEAR(warm.temperature_c(), 38.386, 1e-9);
  // BARO_OUT 49468 * 0.02 mbar.
  EXPECT_NEAR(r.pressure_mbar(), 989.36, 1e-9);
}

TEST(Adis16448BurstTest, DecodesWhatItEncodes) {
  Adis16448Burst b = ReferenceBurst();
  b.crc = b.ComputeCrc();
  std::vector<uint8_t> bytes(Adis16448Burst::Bytes(true));
  ASSERT_TRUE(b.Encode(true, bytes));
  // MSB first: DIAG_STAT 0x0000, then XGYRO_OUT 0x000F.
  EXPECT_EQ(bytes[2], 0x00);
  EXPECT_EQ(bytes[3], 0x0F);
  EXPECT_EQ(bytes[24], 0x9A);
  EXPECT_EQ(bytes[25], 0xF4);
  Adis16448Burst d;
  ASSERT_TRUE(d.Decode(bytes));
  EXPECT_EQ(d.gyro, b.gyro);
  EXPECT_EQ(d.accel, b.accel);
  EXPECT_EQ(d.mag, b.mag);
  EXPECT_EQ(d.baro, b.baro);
  EXPECT_EQ(d.temp, b.temp);
  EXPECT_EQ(d.crc, 0x9AF4);
  EXPECT_FALSE(d.Decode(std::vector<uint8_t>(25)));
  EXPECT_FALSE(b.Encode(false, bytes));  // 26 bytes is not a burst without CRC
}

TEST(Adis16448OptionsTest, RatesAreTheInternalRateOverPowersOfTwo) {
  Adis16448Options options;
  EXPECT_EQ(options.DecimationExponent(), 1);  // 409.6 Hz
  options.rate_hz = 819.2;
  EXPECT_EQ(options.DecimationExponent(), 0);
  options.rate_hz = 102.4;
  EXPECT_EQ(options.DecimationExponent(), 3);
  options.rate_hz = 400.0;
  try {
    options.Validate();
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("rate_hz"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("400"), std::string::npos);
  }
  options.rate_hz = 409.6;
  options.data_ready_line = 3;
  EXPECT_THROW(options.Validate(), std::invalid_argument);
}

TEST(Adis16448RegistersTest, InertialErrorMaskLeavesOutNewDataAlarmsAndMagBaroTests) {
  using namespace adis16448;
  EXPECT_EQ(kDiagInertialErrors & kDiagNewMagBaroData, 0);
  EXPECT_EQ(kDiagInertialErrors & (kDiagAlarm1 | kDiagAlarm2), 0);
  EXPECT_EQ(kDiagInertialErrors & (kDiagMagnetometerTest | kDiagBarometerTest), 0);
  EXPECT_NE(kDiagInertialErrors & kDiagSpiFailure, 0);
  EXPECT_EQ(kDiagInertialErrors, 0xFC7C);
}

}  // namespace
}  // namespace rover::drivers
