// The ADIS16448 driver against the simulated device (SPI protocol, register
// file, burst with CRC) and a fake data-ready line.

#include <gtest/gtest.h>

#include <cerrno>
#include <cstring>
#include <numbers>
#include <string>

#include "drivers/imu/adis16448_driver.h"
#include "drivers/imu/adis16448_registers.h"
#include "drivers/imu/imu_device_error.h"
#include "hil/sim/devices/simulated_adis16448.h"
#include "tests/hil/sim/devices/fake_data_ready.h"
#include "tests/support/allocation_counter.h"
#include "tests/support/malloc_counter.h"

namespace rover {
namespace {

using drivers::Adis16448Driver;
using drivers::Adis16448Options;
using drivers::ImuSample;
using drivers::ReadStatus;
using sim::SimulatedAdis16448;
using sim::SimulatedAdis16448Options;
using testing::FakeDataReady;
namespace adis = drivers::adis16448;

const Duration kPeriod = Duration::FromSeconds(1.0 / 409.6);
const Duration kTimeout = Duration::Milliseconds(100);

// Sample k converted by hand: 0.04 deg/s and 0.833 mg per LSB.
void ExpectSample(const ImuSample& s, const drivers::Adis16448Burst& raw) {
  const double rad_s_per_lsb = 0.04 * std::numbers::pi / 180.0;
  const double m_s2_per_lsb = 0.833e-3 * 9.80665;
  for (int i = 0; i < 3; ++i) {
    const auto k = static_cast<std::size_t>(i);
    EXPECT_NEAR(s.angular_velocity_rad_s[i], raw.gyro[k] * rad_s_per_lsb, 1e-12);
    EXPECT_NEAR(s.linear_acceleration_m_s2[i], raw.accel[k] * m_s2_per_lsb, 1e-12);
  }
}

TEST(Adis16448SimTest, ConfiguresRateDataReadyAndCrc) {
  SimulatedAdis16448 device;
  FakeDataReady data_ready(&device, kPeriod);
  Adis16448Driver driver(device, data_ready, Adis16448Options{});
  EXPECT_EQ(device.register_value(adis::kSmplPrd), 0x0101);  // D = 1, internal clock
  EXPECT_EQ(device.register_value(adis::kMscCtrl), 0x0016);  // CRC, DR enable, active high, DIO1
  EXPECT_DOUBLE_EQ(device.output_rate_hz(), 409.6);
  EXPECT_EQ(driver.period(), kPeriod);
}

TEST(Adis16448SimTest, DeliversConvertedSamplesStampedByTheEdge) {
  SimulatedAdis16448 device;
  FakeDataReady data_ready(&device, kPeriod);
  Adis16448Driver driver(device, data_ready, Adis16448Options{});
  for (uint64_t k = 0; k < 200; ++k) {
    ImuSample s;
    ASSERT_EQ(driver.Read(&s, kTimeout), ReadStatus::kOk);
    EXPECT_EQ(s.sequence, k);
    EXPECT_EQ(s.stamp, data_ready.start() + kPeriod * static_cast<int64_t>(k));
    ExpectSample(s, device.SampleAt(k));
  }
  // The device at rest: about 1 g on z.
  EXPECT_NEAR(driver.last_burst().temperature_c(), 20.07, 0.01);
  const drivers::Adis16448Stats stats = driver.stats();
  EXPECT_EQ(stats.samples, 200u);
  EXPECT_EQ(stats.crc_errors, 0u);
  EXPECT_EQ(stats.missed_edges, 0u);
}

TEST(Adis16448SimTest, DropsBurstsWithABadCrcOrDiagnosticFlags) {
  SimulatedAdis16448Options options;
  options.bad_crc_period = 10;    // bursts 10, 20, ... 100
  options.diag_error_period = 7;  // bursts 7, 14, ... 98 (70 also has a bad CRC)
  SimulatedAdis16448 device(options);
  FakeDataReady data_ready(&device, kPeriod);
  data_ready.EndAt(100);
  Adis16448Driver driver(device, data_ready, Adis16448Options{});
  ImuSample s;
  uint64_t delivered = 0;
  while (driver.Read(&s, kTimeout) == ReadStatus::kOk) {
    ++delivered;
    ExpectSample(s, device.SampleAt(s.sequence));
    // Burst n (1-based) reads sample n - 1: rejected ones leave gaps.
    ASSERT_NE((s.sequence + 1) % 10, 0u);
    ASSERT_NE((s.sequence + 1) % 7, 0u);
  }
  const drivers::Adis16448Stats stats = driver.stats();
  EXPECT_EQ(device.bursts(), 100u);
  EXPECT_EQ(stats.crc_errors, 10u);
  EXPECT_EQ(stats.diag_errors, 13u);  // 14 flagged, one of them already failed its CRC
  EXPECT_EQ(delivered, 100u - 10u - 13u);
  EXPECT_EQ(stats.samples, delivered);
  EXPECT_EQ(stats.timeouts, 1u);
}

TEST(Adis16448SimTest, CountsMissedDataReadyEdges) {
  SimulatedAdis16448 device;
  FakeDataReady data_ready(&device, kPeriod);
  data_ready.Skip(5);
  data_ready.Skip(20);
  data_ready.Skip(21);
  data_ready.EndAt(40);
  Adis16448Driver driver(device, data_ready, Adis16448Options{});
  ImuSample s;
  std::vector<uint64_t> sequences;
  while (driver.Read(&s, kTimeout) == ReadStatus::kOk) {
    sequences.push_back(s.sequence);
    ExpectSample(s, device.SampleAt(s.sequence));
  }
  EXPECT_EQ(sequences.size(), 37u);
  EXPECT_EQ(driver.stats().missed_edges, 3u);
  EXPECT_EQ(sequences[5], 6u);    // 5 is missing
  EXPECT_EQ(sequences[19], 22u);  // 20 and 21 are missing
}

// Edges queued while the process was still starting (here 10) belong to
// samples the sensor no longer holds: Start() drops them, so the first
// sample is the first edge after it, numbered 0, with its own data.
TEST(Adis16448SimTest, StartForgetsTheEdgesQueuedBeforeIt) {
  SimulatedAdis16448 device;
  FakeDataReady data_ready(&device, kPeriod);
  data_ready.EndAt(10);
  Adis16448Driver driver(device, data_ready, Adis16448Options{});
  driver.Start();
  ImuSample s;
  EXPECT_EQ(driver.Read(&s, kTimeout), ReadStatus::kTimeout) << "a queued edge was delivered";
  data_ready.EndAt(20);
  for (uint64_t k = 10; k < 20; ++k) {
    ASSERT_EQ(driver.Read(&s, kTimeout), ReadStatus::kOk);
    EXPECT_EQ(s.sequence, k - 10);
    EXPECT_EQ(s.stamp, data_ready.start() + kPeriod * static_cast<int64_t>(k));
    ExpectSample(s, device.SampleAt(k));
  }
  EXPECT_EQ(driver.stats().samples, 10u);
  EXPECT_EQ(driver.stats().missed_edges, 0u);
}

TEST(Adis16448SimTest, IgnoresTheOtherEdgeOfTheDataReadyPulse) {
  SimulatedAdis16448 device;
  FakeDataReady data_ready(&device, kPeriod);
  data_ready.EmitFallingEdges(true);
  Adis16448Driver driver(device, data_ready, Adis16448Options{});
  ImuSample s;
  for (uint64_t k = 0; k < 20; ++k) {
    ASSERT_EQ(driver.Read(&s, kTimeout), ReadStatus::kOk);
    EXPECT_EQ(s.sequence, k);
  }
  EXPECT_EQ(driver.stats().missed_edges, 0u);
  EXPECT_EQ(device.bursts(), 20u);
}

TEST(Adis16448SimTest, WorksWithoutTheBurstCrc) {
  SimulatedAdis16448 device;
  FakeDataReady data_ready(&device, kPeriod);
  Adis16448Options options;
  options.burst_crc = false;
  options.rate_hz = 204.8;
  Adis16448Driver driver(device, data_ready, options);
  EXPECT_EQ(device.register_value(adis::kMscCtrl), 0x0006);
  EXPECT_EQ(device.register_value(adis::kSmplPrd), 0x0201);
  ImuSample s;
  ASSERT_EQ(driver.Read(&s, kTimeout), ReadStatus::kOk);
  ExpectSample(s, device.SampleAt(0));
}

TEST(Adis16448SimTest, RefusesAnotherProductId) {
  SimulatedAdis16448Options options;
  options.product_id = 0x4050;
  SimulatedAdis16448 device(options);
  FakeDataReady data_ready(&device, kPeriod);
  try {
    Adis16448Driver driver(device, data_ready, Adis16448Options{});
    FAIL() << "expected ImuDeviceError";
  } catch (const drivers::ImuDeviceError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("PROD_ID"), std::string::npos) << what;
    EXPECT_NE(what.find("0x4050"), std::string::npos) << what;
    EXPECT_NE(what.find("0x4040"), std::string::npos) << what;
    EXPECT_NE(what.find("simulated ADIS16448"), std::string::npos) << what;
  }
}

TEST(Adis16448SimTest, NamesTheSystemErrorOfAFailedTransfer) {
  SimulatedAdis16448Options options;
  options.fail_transfers = true;
  SimulatedAdis16448 device(options);
  FakeDataReady data_ready(&device, kPeriod);
  try {
    Adis16448Driver driver(device, data_ready, Adis16448Options{});
    FAIL() << "expected ImuDeviceError";
  } catch (const drivers::ImuDeviceError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(std::strerror(EIO)), std::string::npos) << what;
    EXPECT_NE(what.find("register 0x0056"), std::string::npos) << what;
  }
}

TEST(Adis16448SimTest, ReadDoesNotAllocateAfterStartUp) {
  SimulatedAdis16448Options options;
  options.bad_crc_period = 9;  // the rejection path too
  SimulatedAdis16448 device(options);
  FakeDataReady data_ready(&device, kPeriod);
  data_ready.Skip(50);
  Adis16448Driver driver(device, data_ready, Adis16448Options{});
  ImuSample s;
  ASSERT_EQ(driver.Read(&s, kTimeout), ReadStatus::kOk);
  testing::ScopedAllocationCheck allocations;
  testing::ScopedMallocCheck mallocs;
  for (int i = 0; i < 300; ++i) ASSERT_EQ(driver.Read(&s, kTimeout), ReadStatus::kOk);
  EXPECT_EQ(allocations.allocations(), 0u);
  EXPECT_EQ(mallocs.mallocs(), 0u);
}

}  // namespace
}  // namespace rover
