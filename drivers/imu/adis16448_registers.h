#ifndef ROVER_DRIVERS_IMU_ADIS16448_REGISTERS_H_
#define ROVER_DRIVERS_IMU_ADIS16448_REGISTERS_H_

// Analog Devices ADIS16448 register map and scale factors (data sheet). The
// SPI protocol moves 16-bit frames, MSB first, in SPI mode 3:
//  - read:  send (address << 8); the register's value comes back during the
//           NEXT 16-bit frame (whatever is sent then);
//  - write: one frame per byte, ((address | 0x80) << 8) | byte, the low byte
//           to the even address, the high byte to address + 1;
//  - burst: send 0x3E00 (GLOB_CMD read) and keep clocking: DIAG_STAT,
//           X/Y/Z GYRO_OUT, X/Y/Z ACCL_OUT, X/Y/Z MAGN_OUT, BARO_OUT,
//           TEMP_OUT follow in one chip-select frame, plus a CRC-16 word
//           when MSC_CTRL bit 4 is set.
// Between register frames chip select must stay high for the stall time.

#include <cstdint>
#include <numbers>

namespace rover::drivers::adis16448 {

// Register addresses (16-bit registers at even addresses).
inline constexpr uint8_t kXgyroOut = 0x04;
inline constexpr uint8_t kMscCtrl = 0x34;
inline constexpr uint8_t kSmplPrd = 0x36;
inline constexpr uint8_t kSensAvg = 0x38;
inline constexpr uint8_t kDiagStat = 0x3C;
inline constexpr uint8_t kGlobCmd = 0x3E;
inline constexpr uint8_t kLotId1 = 0x52;
inline constexpr uint8_t kLotId2 = 0x54;
inline constexpr uint8_t kProdId = 0x56;
inline constexpr uint8_t kSerialNum = 0x58;

/// Bit 7 of the first byte of a frame: write.
inline constexpr uint8_t kWriteBit = 0x80;
/// PROD_ID of an ADIS16448.
inline constexpr uint16_t kProductId = 0x4040;
/// The burst-read command frame (a read of GLOB_CMD).
inline constexpr uint16_t kBurstCommand = 0x3E00;

// MSC_CTRL bits.
inline constexpr uint16_t kMscDataReadyDio2 = 1u << 0;        ///< 1: DIO2, 0: DIO1
inline constexpr uint16_t kMscDataReadyActiveHigh = 1u << 1;  ///< polarity
inline constexpr uint16_t kMscDataReadyEnable = 1u << 2;
inline constexpr uint16_t kMscBurstCrc = 1u << 4;  ///< append CRC-16 to burst output

// SMPL_PRD: bits [12:8] hold D, the output rate is 819.2 SPS / 2^D; bit 0
// selects the internal sample clock.
inline constexpr double kInternalSampleRateHz = 819.2;
inline constexpr uint16_t kSmplPrdInternalClock = 1u << 0;
inline constexpr int kSmplPrdDecimationShift = 8;
inline constexpr int kMaxDecimationExponent = 10;

// DIAG_STAT bits.
inline constexpr uint16_t kDiagMagnetometerTest = 1u << 0;
inline constexpr uint16_t kDiagBarometerTest = 1u << 1;
inline constexpr uint16_t kDiagSpiFailure = 1u << 3;
inline constexpr uint16_t kDiagNewMagBaroData = 1u << 7;
inline constexpr uint16_t kDiagAlarm1 = 1u << 8;
inline constexpr uint16_t kDiagAlarm2 = 1u << 9;
/// Flags that make the inertial data of a burst untrustworthy: axis
/// self-test failures (15..10), flash checksum (6), self-test (5), overrange
/// (4), SPI failure (3), flash update (2). Not: the new-data flag, the
/// user-programmed alarms and the magnetometer/barometer tests, which say
/// nothing about gyro and accelerometer.
inline constexpr uint16_t kDiagInertialErrors = static_cast<uint16_t>(
    0xFFFFu & ~static_cast<unsigned>(kDiagMagnetometerTest | kDiagBarometerTest |
                                     kDiagNewMagBaroData | kDiagAlarm1 | kDiagAlarm2));

// Scale factors of the output registers (two's complement).
inline constexpr double kStandardGravityM_s2 = 9.80665;
inline constexpr double kGyroDegSPerLsb = 0.04;  ///< +-1000 deg/s range
inline constexpr double kGyroRadSPerLsb = kGyroDegSPerLsb * std::numbers::pi / 180.0;
inline constexpr double kAccelGPerLsb = 0.833e-3;  ///< +-18 g range
inline constexpr double kAccelM_s2PerLsb = kAccelGPerLsb * kStandardGravityM_s2;
inline constexpr double kMagGaussPerLsb = 142.9e-6;
inline constexpr double kBaroMbarPerLsb = 0.02;  ///< BARO_OUT is unsigned
inline constexpr double kTempCPerLsb = 0.07386;  ///< TEMP_OUT: 12-bit two's complement
inline constexpr double kTempOffsetC = 31.0;     ///< TEMP_OUT = 0 at 31 degC

}  // namespace rover::drivers::adis16448

#endif  // ROVER_DRIVERS_IMU_ADIS16448_REGISTERS_H_
