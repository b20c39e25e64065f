#ifndef ROVER_DRIVERS_IMU_ADIS16448_BURST_H_
#define ROVER_DRIVERS_IMU_ADIS16448_BURST_H_

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "drivers/imu/imu_sample.h"

namespace rover::drivers {

/// The output of one ADIS16448 burst read, as raw register words.
struct Adis16448Burst {
  uint16_t diag_stat = 0;
  std::array<int16_t, 3> gyro{};   ///< X/Y/ZGYRO_OUT, 0.04 deg/s per LSB
  std::array<int16_t, 3> accel{};  ///< X/Y/ZACCL_OUT, 0.833 mg per LSB
  std::array<int16_t, 3> mag{};    ///< X/Y/ZMAGN_OUT, 142.9 ugauss per LSB
  uint16_t baro = 0;               ///< BARO_OUT, 0.02 mbar per LSB
  uint16_t temp = 0;               ///< TEMP_OUT, 12-bit two's complement
  uint16_t crc = 0;                ///< the CRC-16 word, when the burst carries one

  /// Bytes the device sends after the command word: 12 words, 13 with CRC.
  static constexpr std::size_t Bytes(bool with_crc) { return with_crc ? 26 : 24; }

  /// The CRC-16 the device appends (MSC_CTRL bit 4), as the received word:
  /// CRC-16-CCITT (polynomial 0x1021, initial value 0xFFFF) in its
  /// LSB-first (reflected-input) form over XGYRO_OUT..TEMP_OUT (11 words,
  /// DIAG_STAT excluded), each word fed low byte first; the result
  /// complemented, then its bytes swapped.
  uint16_t ComputeCrc() const;

  /// Decodes the bytes following the command word, MSB first per word:
  /// `bytes` holds Bytes(false) or Bytes(true) bytes (anything else: false).
  bool Decode(std::span<const uint8_t> bytes);
  /// Writes the burst output (with the crc field when `with_crc`) to `out`,
  /// which must hold Bytes(with_crc) bytes; false otherwise.
  bool Encode(bool with_crc, std::span<uint8_t> out) const;

  /// Temperature in degC.
  double temperature_c() const;
  /// Pressure in mbar (hPa).
  double pressure_mbar() const;
  /// Converts gyro and accelerometer words to SI units (rad/s, m/s^2) in
  /// the sensor's axes. Stamp and sequence are left as they are.
  void ToSample(ImuSample* sample) const;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_IMU_ADIS16448_BURST_H_
