#ifndef ROVER_HIL_SIM_DEVICES_SIMULATED_MTI_H_
#define ROVER_HIL_SIM_DEVICES_SIMULATED_MTI_H_

// An Xsens MTi on the far side of a pseudo-terminal, for testing the real
// serial driver (drivers/imu/xsens_mti_driver.h) without hardware: the
// driver opens port() exactly as it would open /dev/ttyUSB0.

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <mutex>
#include <random>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "core/time/time.h"
#include "drivers/imu/mt_data2_packet.h"
#include "drivers/imu/xbus_parser.h"

namespace rover::sim {

struct SimulatedMtiOptions {
  uint32_t device_id = 0x0380'1A2Bu;  ///< answered to ReqDID
  uint64_t seed = 1;                  ///< signal noise and fault decisions
  /// False: a dead device that reads everything and never answers.
  bool answer = true;
  /// Power up streaming (as a real MTi does) at start_rate_hz with all four
  /// items, before anyone configures it.
  bool start_in_measurement = false;
  int start_rate_hz = 400;
  /// Highest output rate SetOutputConfiguration accepts; above: Error 0x03.
  int max_rate_hz = 2000;
  uint16_t first_packet_counter = 0;    ///< PacketCounter of packet 0 of a measurement
  uint32_t first_sample_time_fine = 0;  ///< SampleTimeFine at power-up (construction)
  /// The device clock runs this much fast against CLOCK_MONOTONIC.
  double clock_drift_ppm = 0.0;
  /// The measurement of packet k of a measurement at `rate_hz` (counter and
  /// sample time are the device's own); called on the device thread, in
  /// order of k. Empty: PacketAt() (smooth motion plus seeded noise). `rover-sim
  /// mti` sets it to the simulator's IMU along a scenario's route.
  std::function<drivers::MtData2Packet(uint64_t k, int rate_hz)> packet_source{};

  // Fault injection, decided per packet from the seeded stream.
  double drop_probability = 0.0;     ///< packet never sent (a PacketCounter gap)
  double flip_probability = 0.0;     ///< one payload or checksum byte flipped
  double garbage_probability = 0.0;  ///< random bytes sent before the packet
  int garbage_max_bytes = 16;        ///< 1..this many garbage bytes

  /// Throws std::invalid_argument naming the field.
  void Validate() const;
};

struct SimulatedMtiStats {
  uint64_t packets = 0;          ///< MTData2 packets generated (sent or dropped)
  uint64_t intact_packets = 0;   ///< sent unmodified (see write_overflows)
  uint64_t flipped_packets = 0;  ///< sent with a flipped byte
  uint64_t dropped_packets = 0;  ///< not sent
  uint64_t garbage_bytes = 0;    ///< random bytes sent between frames
  uint64_t messages = 0;         ///< valid frames received from the host
  uint64_t errors_sent = 0;      ///< Error (0x42) answers
  uint64_t write_overflows = 0;  ///< frames cut because nobody read the pty
};

/// A simulated MTi owning the master side of a pty pair. Its thread answers
/// GoToConfig, ReqDID, SetOutputConfiguration (PacketCounter, SampleTimeFine,
/// Acceleration, RateOfTurn; echoing the configuration) and GoToMeasurement
/// like the device, and Error 0x42 (code 0x04, invalid message) to anything
/// else or out of place; in measurement mode it sends MTData2 at the
/// configured rate, each packet at its absolute deadline on the device
/// clock (clock_nanosleep TIMER_ABSTIME), values from PacketAt().
class SimulatedMti {
 public:
  /// Opens the pty pair (posix_openpt, grantpt, unlockpt, ptsname), puts the
  /// slave in raw mode and starts the device thread. Throws
  /// std::runtime_error with strerror if the system has no ptys left.
  explicit SimulatedMti(const SimulatedMtiOptions& options);
  /// Stops the thread and closes the pty.
  ~SimulatedMti();
  SimulatedMti(const SimulatedMti&) = delete;
  SimulatedMti& operator=(const SimulatedMti&) = delete;

  /// The slave device to open, e.g. "/dev/pts/7".
  const std::string& port() const { return slave_path_; }
  /// Stops generating packets (the device goes quiet but stays in
  /// measurement mode), so that a reader can drain what was sent.
  void StopStreaming();
  bool measuring() const { return measuring_.load(); }
  SimulatedMtiStats stats() const;
  /// PacketCounter of every packet sent intact, in order.
  std::vector<uint16_t> intact_counters() const;
  /// Output rate of the current measurement, Hz.
  int rate_hz() const { return rate_hz_.load(); }

  /// The measurement values of packet k of a measurement (all four items;
  /// counter and sample time relative to zero): smooth motion plus seeded
  /// noise, identical for the same seed and k.
  static drivers::MtData2Packet PacketAt(uint64_t seed, uint64_t k, int rate_hz);

 private:
  void Run();
  void HandleInput();
  void Handle(const drivers::xbus::Message& message);
  void Send(uint8_t mid, std::span<const uint8_t> payload);
  void SendError(uint8_t code);
  void WriteBytes(std::span<const uint8_t> bytes);
  void StartMeasurement(Time now);
  void SendPacket();
  uint32_t DeviceTicks(Time t) const;

  SimulatedMtiOptions options_;
  int master_fd_ = -1;
  int slave_fd_ = -1;
  std::string slave_path_;
  Time power_up_;

  drivers::XbusParser parser_;
  std::mt19937_64 faults_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> streaming_{true};
  std::atomic<bool> measuring_{false};
  std::atomic<int> rate_hz_{0};
  std::array<bool, 4> configured_ = {true, true, true, true};  // counter, time, accel, gyro

  // Measurement state (device thread only).
  Time measurement_start_;
  uint32_t measurement_ticks_ = 0;  // SampleTimeFine of packet 0
  uint64_t next_packet_ = 0;

  mutable std::mutex mutex_;  // guards stats_ and intact_
  SimulatedMtiStats stats_{};
  std::vector<uint16_t> intact_;
  std::thread thread_;
};

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_DEVICES_SIMULATED_MTI_H_
