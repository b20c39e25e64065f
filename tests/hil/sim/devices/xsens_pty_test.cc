// The Xsens MTi driver against a simulated MTi on a pty pair: the driver
// opens the pty slave exactly as it would open a USB serial adapter.

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "drivers/imu/imu_device_error.h"
#include "drivers/imu/xsens_mti_driver.h"
#include "hil/sim/devices/simulated_mti.h"
#include "tests/support/allocation_counter.h"
#include "tests/support/malloc_counter.h"

namespace rover {
namespace {

using drivers::ImuSample;
using drivers::ReadStatus;
using drivers::XsensMtiDriver;
using drivers::XsensMtiOptions;
using sim::SimulatedMti;
using sim::SimulatedMtiOptions;

// Generous: the machine running the tests may be busy.
constexpr Duration kReadTimeout = Duration::Seconds(2);

XsensMtiOptions DriverOptions(const SimulatedMti& mti, std::vector<std::string>* log = nullptr) {
  XsensMtiOptions options;
  options.port = mti.port();
  options.rate_hz = 400.0;
  options.log = [log](const std::string& line) {
    if (log != nullptr) log->push_back(line);
  };
  return options;
}

// The sample the simulated device sent as packet k of its measurement.
void ExpectSameValues(const ImuSample& s, const drivers::MtData2Packet& p) {
  for (int i = 0; i < 3; ++i) {
    const auto k = static_cast<std::size_t>(i);
    ASSERT_EQ(s.angular_velocity_rad_s[i], static_cast<double>(p.rate_of_turn_rad_s[k]));
    ASSERT_EQ(s.linear_acceleration_m_s2[i], static_cast<double>(p.acceleration_m_s2[k]));
  }
}

TEST(XsensPtyTest, ConfiguresTheDeviceAndLogsItsId) {
  SimulatedMtiOptions sim_options;
  sim_options.device_id = 0x0380'1A2Bu;
  SimulatedMti mti(sim_options);
  std::vector<std::string> log;
  XsensMtiDriver driver(DriverOptions(mti, &log));
  EXPECT_EQ(driver.device_id(), 0x0380'1A2Bu);
  EXPECT_TRUE(mti.measuring());
  EXPECT_EQ(mti.rate_hz(), 400);
  ASSERT_EQ(log.size(), 1u);
  EXPECT_NE(log[0].find("0x03801A2B"), std::string::npos) << log[0];
  EXPECT_NE(log[0].find(mti.port()), std::string::npos) << log[0];
  // GoToConfig, ReqDID, SetOutputConfiguration, GoToMeasurement.
  EXPECT_EQ(mti.stats().messages, 4u);
  EXPECT_EQ(mti.stats().errors_sent, 0u);
}

TEST(XsensPtyTest, StreamsFourHundredHertzWithMonotonicStamps) {
  SimulatedMtiOptions sim_options;
  sim_options.seed = 3;
  SimulatedMti mti(sim_options);
  XsensMtiDriver driver(DriverOptions(mti));
  std::vector<ImuSample> samples(800);
  for (ImuSample& s : samples) {
    ASSERT_EQ(driver.Read(&s, kReadTimeout), ReadStatus::kOk);
    const Time now = Time::Now();
    // The stamp is the device's sample time: never after the bytes arrived,
    // and close before (a pty adds microseconds; allow a stalled machine).
    ASSERT_LE(s.stamp, now);
    ASSERT_GT(s.stamp, now - Duration::Seconds(5));
  }
  for (std::size_t i = 1; i < samples.size(); ++i) {
    ASSERT_EQ(samples[i].sequence, samples[i - 1].sequence + 1) << i;
    ASSERT_GT(samples[i].stamp, samples[i - 1].stamp) << i;
  }
  for (const ImuSample& s : samples) {
    ExpectSameValues(s, SimulatedMti::PacketAt(3, s.sequence, 400));
  }
  const double rate_hz = static_cast<double>(samples.size() - 1) /
                         (samples.back().stamp - samples.front().stamp).ToSeconds();
  EXPECT_GT(rate_hz, 360.0);
  EXPECT_LT(rate_hz, 440.0);
  // 799 periods of the device clock: 1.9975 s, whatever the host's delays.
  EXPECT_NEAR((samples.back().stamp - samples.front().stamp).ToSeconds(), 1.9975, 0.01);
  const drivers::XsensMtiStats stats = driver.stats();
  EXPECT_EQ(stats.samples, 800u);
  EXPECT_EQ(stats.lost_samples, 0u);
  EXPECT_EQ(stats.checksum_errors, 0u);
  EXPECT_EQ(stats.garbage_bytes, 0u);
  EXPECT_EQ(stats.malformed_packets, 0u);
  EXPECT_EQ(stats.read_errors, 0u);
  EXPECT_EQ(stats.non_monotonic_stamps, 0u);
}

// With defer_measurement the device is configured but silent until Start():
// nothing streams into the serial line's buffer while roverd still opens
// its other devices.
TEST(XsensPtyTest, DeferredMeasurementStreamsOnlyFromStart) {
  SimulatedMti mti(SimulatedMtiOptions{});
  std::vector<std::string> log;
  XsensMtiOptions options = DriverOptions(mti, &log);
  options.defer_measurement = true;
  XsensMtiDriver driver(options);
  EXPECT_FALSE(mti.measuring());
  ASSERT_EQ(log.size(), 1u);
  EXPECT_NE(log[0].find("configured for 400 Hz"), std::string::npos) << log[0];
  ImuSample s;
  EXPECT_EQ(driver.Read(&s, Duration::Milliseconds(100)), ReadStatus::kTimeout);
  driver.Start();
  EXPECT_TRUE(mti.measuring());
  driver.Start();  // once only: no second GoToMeasurement
  EXPECT_EQ(mti.stats().messages, 4u);
  for (int i = 0; i < 100; ++i) {
    ASSERT_EQ(driver.Read(&s, kReadTimeout), ReadStatus::kOk);
    EXPECT_EQ(s.sequence, static_cast<uint64_t>(i));
  }
  EXPECT_EQ(driver.stats().lost_samples, 0u);
}

TEST(XsensPtyTest, ConfiguresADeviceThatIsAlreadyStreaming) {
  SimulatedMtiOptions sim_options;
  sim_options.start_in_measurement = true;
  sim_options.start_rate_hz = 100;
  SimulatedMti mti(sim_options);
  XsensMtiDriver driver(DriverOptions(mti));
  EXPECT_EQ(mti.rate_hz(), 400);
  ImuSample s;
  for (int i = 0; i < 50; ++i) ASSERT_EQ(driver.Read(&s, kReadTimeout), ReadStatus::kOk);
  EXPECT_EQ(driver.stats().lost_samples, 0u);
}

TEST(XsensPtyTest, ExtendsThePacketCounterAcrossItsWrap) {
  SimulatedMtiOptions sim_options;
  sim_options.first_packet_counter = 65'500;
  SimulatedMti mti(sim_options);
  XsensMtiDriver driver(DriverOptions(mti));
  ImuSample s;
  ASSERT_EQ(driver.Read(&s, kReadTimeout), ReadStatus::kOk);
  const uint64_t first = s.sequence;
  EXPECT_GE(first, 65'500u);
  for (int i = 1; i < 120; ++i) {
    ASSERT_EQ(driver.Read(&s, kReadTimeout), ReadStatus::kOk);
    ASSERT_EQ(s.sequence, first + static_cast<uint64_t>(i));
  }
  EXPECT_GT(s.sequence, 65'535u);
  EXPECT_EQ(driver.stats().lost_samples, 0u);
  EXPECT_EQ(driver.stats().counter_resets, 0u);
}

// Garbage between frames, flipped bytes and dropped packets: every intact
// packet still arrives, in order and with its own values, the flipped and
// dropped ones are counted as lost, and the rejected bytes as checksum
// errors and garbage.
TEST(XsensPtyTest, ResyncsAfterCorruptionAndDeliversEveryIntactPacket) {
  SimulatedMtiOptions sim_options;
  sim_options.seed = 11;
  sim_options.garbage_probability = 0.05;
  sim_options.flip_probability = 0.02;
  sim_options.drop_probability = 0.01;
  SimulatedMti mti(sim_options);
  XsensMtiDriver driver(DriverOptions(mti));
  std::vector<ImuSample> samples;
  ImuSample s;
  while (mti.stats().packets < 1000) {
    ASSERT_EQ(driver.Read(&s, kReadTimeout), ReadStatus::kOk);
    samples.push_back(s);
  }
  mti.StopStreaming();
  ReadStatus status;
  while ((status = driver.Read(&s, Duration::Milliseconds(300))) == ReadStatus::kOk) {
    samples.push_back(s);
  }
  ASSERT_EQ(status, ReadStatus::kTimeout);

  const sim::SimulatedMtiStats sent = mti.stats();
  const std::vector<uint16_t> intact = mti.intact_counters();
  ASSERT_GT(sent.flipped_packets, 5u);
  ASSERT_GT(sent.dropped_packets, 2u);
  ASSERT_GT(sent.garbage_bytes, 100u);
  ASSERT_EQ(sent.write_overflows, 0u);
  ASSERT_EQ(samples.size(), intact.size());
  for (std::size_t i = 0; i < samples.size(); ++i) {
    ASSERT_EQ(static_cast<uint16_t>(samples[i].sequence), intact[i]) << i;
    ExpectSameValues(samples[i], SimulatedMti::PacketAt(11, samples[i].sequence, 400));
    if (i > 0) {
      ASSERT_GT(samples[i].sequence, samples[i - 1].sequence);
      ASSERT_GT(samples[i].stamp, samples[i - 1].stamp);
    }
  }
  const drivers::XsensMtiStats stats = driver.stats();
  EXPECT_EQ(stats.samples, samples.size());
  EXPECT_EQ(stats.lost_samples,
            samples.back().sequence - samples.front().sequence + 1 - samples.size());
  // A flipped payload or checksum byte always breaks the sum.
  EXPECT_GE(stats.checksum_errors, sent.flipped_packets);
  EXPECT_EQ(stats.malformed_packets, 0u);
  EXPECT_GE(stats.garbage_bytes, sent.garbage_bytes);
  EXPECT_GT(stats.resyncs, 0u);
}

TEST(XsensPtyTest, NamesThePortAndTheStepWhenTheDeviceDoesNotAnswer) {
  SimulatedMtiOptions sim_options;
  sim_options.answer = false;
  SimulatedMti mti(sim_options);
  XsensMtiOptions options = DriverOptions(mti);
  options.ack_timeout = Duration::Milliseconds(100);
  options.attempts = 2;
  try {
    XsensMtiDriver driver(options);
    FAIL() << "expected ImuDeviceError";
  } catch (const drivers::ImuDeviceError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(mti.port()), std::string::npos) << what;
    EXPECT_NE(what.find("GoToConfig"), std::string::npos) << what;
    EXPECT_NE(what.find("does not answer"), std::string::npos) << what;
    EXPECT_NE(what.find("2 attempt"), std::string::npos) << what;
  }
  // One GoToConfig per attempt (the device thread may still be reading).
  for (int i = 0; i < 200 && mti.stats().messages < 2; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_EQ(mti.stats().messages, 2u);
}

TEST(XsensPtyTest, ReportsTheDevicesErrorCode) {
  SimulatedMtiOptions sim_options;
  sim_options.max_rate_hz = 200;
  sim_options.start_rate_hz = 100;
  SimulatedMti mti(sim_options);
  try {
    XsensMtiDriver driver(DriverOptions(mti));
    FAIL() << "expected ImuDeviceError";
  } catch (const drivers::ImuDeviceError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(mti.port()), std::string::npos) << what;
    EXPECT_NE(what.find("SetOutputConfiguration"), std::string::npos) << what;
    EXPECT_NE(what.find("0x03"), std::string::npos) << what;
    EXPECT_NE(what.find("invalid period"), std::string::npos) << what;
  }
}

TEST(XsensPtyTest, NamesAMissingPort) {
  XsensMtiOptions options;
  options.port = "/dev/ttyUSB-no-such-imu";
  try {
    XsensMtiDriver driver(options);
    FAIL() << "expected ImuDeviceError";
  } catch (const drivers::ImuDeviceError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("/dev/ttyUSB-no-such-imu"), std::string::npos) << what;
    EXPECT_NE(what.find("No such file or directory"), std::string::npos) << what;
  }
}

TEST(XsensPtyTest, TimesOutWhenTheDeviceGoesQuiet) {
  SimulatedMti mti(SimulatedMtiOptions{});
  XsensMtiDriver driver(DriverOptions(mti));
  ImuSample s;
  ASSERT_EQ(driver.Read(&s, kReadTimeout), ReadStatus::kOk);
  mti.StopStreaming();
  while (driver.Read(&s, Duration::Milliseconds(100)) == ReadStatus::kOk) {
  }
  EXPECT_EQ(driver.Read(&s, Duration::Milliseconds(20)), ReadStatus::kTimeout);
  EXPECT_GE(driver.stats().timeouts, 2u);
}

TEST(XsensPtyTest, ReportsAnErrorWhenThePortHangsUp) {
  auto mti = std::make_unique<SimulatedMti>(SimulatedMtiOptions{});
  XsensMtiDriver driver(DriverOptions(*mti));
  ImuSample s;
  ASSERT_EQ(driver.Read(&s, kReadTimeout), ReadStatus::kOk);
  mti.reset();  // closes the master side
  ReadStatus status = ReadStatus::kOk;
  for (int i = 0; i < 1000 && status == ReadStatus::kOk; ++i)
    status = driver.Read(&s, kReadTimeout);
  EXPECT_EQ(status, ReadStatus::kError);
  EXPECT_EQ(driver.stats().read_errors, 1u);
}

TEST(XsensPtyTest, ReadDoesNotAllocateAfterStartUp) {
  SimulatedMtiOptions sim_options;
  sim_options.garbage_probability = 0.05;  // the resync path too
  sim_options.flip_probability = 0.02;
  SimulatedMti mti(sim_options);
  XsensMtiDriver driver(DriverOptions(mti));
  ImuSample s;
  ASSERT_EQ(driver.Read(&s, kReadTimeout), ReadStatus::kOk);
  testing::ScopedAllocationCheck allocations;
  testing::ScopedMallocCheck mallocs;
  int ok = 0;
  for (int i = 0; i < 300; ++i) ok += driver.Read(&s, kReadTimeout) == ReadStatus::kOk ? 1 : 0;
  (void)driver.Read(&s, Duration::Zero());  // the timeout path
  EXPECT_EQ(allocations.allocations(), 0u);
  EXPECT_EQ(mallocs.mallocs(), 0u);
  EXPECT_EQ(ok, 300);
}

}  // namespace
}  // namespace rover
