#include "drivers/imu/adis16448_burst.h"

#include "drivers/imu/adis16448_registers.h"

namespace rover::drivers {
namespace {

uint16_t Word(const uint8_t* p) {
  return static_cast<uint16_t>((static_cast<unsigned>(p[0]) << 8) | p[1]);
}
void PutWord(uint16_t w, uint8_t* p) {
  p[0] = static_cast<uint8_t>(w >> 8);
  p[1] = static_cast<uint8_t>(w);
}

// Feeds one byte, least significant bit first, into the reflected CRC.
uint16_t CrcByte(uint16_t crc, uint8_t byte) {
  constexpr uint16_t kPolynomial = 0x1021;
  unsigned data = byte;
  for (int bit = 0; bit < 8; ++bit, data >>= 1) {
    const bool feedback = ((crc ^ data) & 1u) != 0;
    crc = static_cast<uint16_t>(crc >> 1);
    if (feedback) crc = static_cast<uint16_t>(crc ^ kPolynomial);
  }
  return crc;
}

}  // namespace

uint16_t Adis16448Burst::ComputeCrc() const {
  const std::array<uint16_t, 11> words = {static_cast<uint16_t>(gyro[0]),
                                          static_cast<uint16_t>(gyro[1]),
                                          static_cast<uint16_t>(gyro[2]),
                                          static_cast<uint16_t>(accel[0]),
                                          static_cast<uint16_t>(accel[1]),
                                          static_cast<uint16_t>(accel[2]),
                                          static_cast<uint16_t>(mag[0]),
                                          static_cast<uint16_t>(mag[1]),
                                          static_cast<uint16_t>(mag[2]),
                                          baro,
                                          temp};
  uint16_t value = 0xFFFF;
  for (const uint16_t w : words) {
    value = CrcByte(value, static_cast<uint8_t>(w & 0xFFu));
    value = CrcByte(value, static_cast<uint8_t>(w >> 8));
  }
  value = static_cast<uint16_t>(~value);
  return static_cast<uint16_t>((value << 8) | (value >> 8));
}

bool Adis16448Burst::Decode(std::span<const uint8_t> bytes) {
  const bool with_crc = bytes.size() == Bytes(true);
  if (!with_crc && bytes.size() != Bytes(false)) return false;
  const uint8_t* p = bytes.data();
  diag_stat = Word(p);
  for (std::size_t i = 0; i < 3; ++i) {
    gyro[i] = static_cast<int16_t>(Word(p + 2 + 2 * i));
    accel[i] = static_cast<int16_t>(Word(p + 8 + 2 * i));
    mag[i] = static_cast<int16_t>(Word(p + 14 + 2 * i));
  }
  baro = Word(p + 20);
  temp = Word(p + 22);
  crc = with_crc ? Word(p + 24) : 0;
  return true;
}

bool Adis16448Burst::Encode(bool with_crc, std::span<uint8_t> out) const {
  if (out.size() != Bytes(with_crc)) return false;
  uint8_t* p = out.data();
  PutWord(diag_stat, p);
  for (std::size_t i = 0; i < 3; ++i) {
    PutWord(static_cast<uint16_t>(gyro[i]), p + 2 + 2 * i);
    PutWord(static_cast<uint16_t>(accel[i]), p + 8 + 2 * i);
    PutWord(static_cast<uint16_t>(mag[i]), p + 14 + 2 * i);
  }
  PutWord(baro, p + 20);
  PutWord(temp, p + 22);
  if (with_crc) PutWord(crc, p + 24);
  return true;
}

double Adis16448Burst::temperature_c() const {
  // Sign-extend the 12-bit value.
  int value = temp & 0x0FFF;
  if ((value & 0x0800) != 0) value -= 0x1000;
  return adis16448::kTempOffsetC + adis16448::kTempCPerLsb * value;
}

double Adis16448Burst::pressure_mbar() const { return adis16448::kBaroMbarPerLsb * baro; }

void Adis16448Burst::ToSample(ImuSample* sample) const {
  for (int i = 0; i < 3; ++i) {
    const auto k = static_cast<std::size_t>(i);
    sample->angular_velocity_rad_s[i] = adis16448::kGyroRadSPerLsb * gyro[k];
    sample->linear_acceleration_m_s2[i] = adis16448::kAccelM_s2PerLsb * accel[k];
  }
}

}  // namespace rover::drivers
