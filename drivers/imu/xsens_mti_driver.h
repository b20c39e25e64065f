#ifndef ROVER_DRIVERS_IMU_XSENS_MTI_DRIVER_H_
#define ROVER_DRIVERS_IMU_XSENS_MTI_DRIVER_H_

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "core/time/time.h"
#include "drivers/imu/clock_offset_tracker.h"
#include "drivers/imu/imu_driver.h"
#include "drivers/imu/mt_data2_packet.h"
#include "drivers/imu/serial_port.h"
#include "drivers/imu/xbus_parser.h"

namespace rover::drivers {

struct XsensMtiOptions {
  std::string port = "/dev/ttyUSB0";  ///< the MTi's UART or USB serial device (or a pty)
  int baud_rate = 921600;             ///< must match the device's configured rate
  /// Output rate of acceleration and rate of turn: an integer in [1, 2000]
  /// the device supports (MTi 1/10/100-series: divisors of its internal
  /// rate; 400 Hz is the usual maximum for calibrated inertial data).
  double rate_hz = 400.0;
  /// How long each handshake step waits for its acknowledge per attempt.
  Duration ack_timeout = Duration::Milliseconds(500);
  /// Attempts per handshake step before giving up, >= 1.
  int attempts = 3;
  /// Device-clock-to-monotonic mapping of the sample stamps.
  ClockOffsetTrackerOptions clock;
  /// Constant transport delay subtracted from every stamp (the part of the
  /// serial delay the offset tracker cannot see: at least the frame's
  /// transmission time, 10 bits per byte at baud_rate). Zero by default.
  Duration latency_correction = Duration::Zero();
  /// Start-up messages (the device id). Null: written to stderr.
  std::function<void(const std::string&)> log;
  /// True: construction leaves the device in configuration mode and Start()
  /// sends GoToMeasurement, so that nothing streams (and overflows the
  /// serial line's buffer) before the reader is ready. False: construction
  /// starts the measurement, for a reader that follows at once.
  bool defer_measurement = false;

  /// Throws std::invalid_argument naming the field, the expected range and
  /// the value found.
  void Validate() const;
};

/// Health counters of an XsensMtiDriver (cumulative since start-up).
struct XsensMtiStats {
  uint64_t samples = 0;               ///< samples delivered
  uint64_t lost_samples = 0;          ///< PacketCounter gaps (packets never delivered)
  uint64_t checksum_errors = 0;       ///< frames rejected by their checksum
  uint64_t garbage_bytes = 0;         ///< bytes outside any valid frame
  uint64_t resyncs = 0;               ///< times the byte stream lost frame alignment
  uint64_t oversize_frames = 0;       ///< frame starts announcing impossible lengths
  uint64_t malformed_packets = 0;     ///< valid MTData2 frames with bad or missing items
  uint64_t duplicate_packets = 0;     ///< packets repeating the previous PacketCounter
  uint64_t counter_resets = 0;        ///< PacketCounter jumped back (device restarted)
  uint64_t clock_resets = 0;          ///< SampleTimeFine jumped back (device restarted)
  uint64_t non_monotonic_stamps = 0;  ///< stamps moved forward to keep them increasing
  uint64_t device_errors = 0;         ///< Error (0x42) messages in measurement mode
  uint64_t timeouts = 0;              ///< Read() calls that returned kTimeout
  uint64_t read_errors = 0;           ///< poll/read failures, hang-ups
};

/// An Xsens MTi (1/10/100-series) on a serial port, speaking Xbus.
///
/// Construction opens the port raw (SerialPort) and runs the start-up
/// handshake, each step waiting for its acknowledge with `ack_timeout` and
/// `attempts` tries: GoToConfig (0x30 -> 0x31), ReqDID (0x00 -> DeviceID
/// 0x01, logged), SetOutputConfiguration (0xC0 -> 0xC1: PacketCounter and
/// SampleTimeFine with every packet, Acceleration and RateOfTurn as float32
/// at rate_hz), GoToMeasurement (0x10 -> 0x11). MTData2 still streaming from
/// an earlier session is ignored while it waits.
///
/// Read() then turns MTData2 packets into ImuSamples:
///  - sequence: PacketCounter extended to 64 bits; a forward gap of n counts
///    n - 1 lost samples (across the uint16 wrap as well);
///  - stamp: SampleTimeFine (10 kHz device ticks, unwrapped to 64 bits)
///    mapped onto CLOCK_MONOTONIC by a ClockOffsetTracker fed with the time
///    the bytes were read. The host receive time itself jitters with the
///    serial delay (UART FIFO, USB polling, scheduling: up to milliseconds);
///    the device's sample clock does not, and the tracker's lower envelope of
///    (receive - device time) keeps that jitter out of the stamp.
/// Frames announcing more than 254 payload bytes are refused as impossible:
/// nothing this driver configures is that long, and the limit bounds how
/// long a false frame start in corrupted bytes can hold back the packets
/// behind it (259 bytes, instead of 2055 with extended lengths).
/// After construction Read() never allocates, throws or locks, and blocks at
/// most `timeout` (ppoll on the port).
class XsensMtiDriver final : public ImuDriver {
 public:
  /// Opens `options.port` and runs the handshake. Throws ImuDeviceError
  /// naming the port, the step and the cause: a system error (strerror), no
  /// acknowledge after every attempt ("the device does not answer"), or an
  /// Error message with its code. std::invalid_argument for bad options.
  explicit XsensMtiDriver(const XsensMtiOptions& options);
  XsensMtiDriver(const XsensMtiDriver&) = delete;
  XsensMtiDriver& operator=(const XsensMtiDriver&) = delete;

  /// Waits up to `timeout` for the next complete MTData2 packet and fills
  /// *sample. kTimeout if none completed in time, kError if the port failed
  /// (read error or hang-up; counted in read_errors). Frames that fail the
  /// checksum, other messages and malformed packets are counted and skipped
  /// within the same call.
  ReadStatus Read(ImuSample* sample, Duration timeout) override;
  /// With defer_measurement, GoToMeasurement (throws ImuDeviceError like the
  /// handshake); otherwise, or when measuring already, nothing.
  void Start() override;

  /// Health counters so far. Safe to call from the reading thread only.
  XsensMtiStats stats() const;
  /// The DeviceID the device reported at start-up.
  uint64_t device_id() const { return device_id_; }
  const std::string& port() const { return port_.path(); }

 private:
  // Sends a request and returns the payload of its acknowledge `ack_mid`.
  std::vector<uint8_t> Request(uint8_t mid, std::span<const uint8_t> payload, uint8_t ack_mid,
                               const char* step);
  void Configure();
  void GoToMeasurement();
  // Reads what the port has into the parser; false on error or hang-up.
  // `*timed_out` is set if nothing arrived before `deadline`.
  bool ReadInto(Time deadline, bool* timed_out);
  // Turns a decoded packet into *sample; false if it must be skipped.
  bool ToSample(const MtData2Packet& packet, ImuSample* sample);

  XsensMtiOptions options_;
  SerialPort port_;
  XbusParser parser_;
  ClockOffsetTracker clock_;
  uint64_t device_id_ = 0;
  bool measuring_ = false;
  Time last_read_time_;  // when the bytes now in the parser had arrived (upper bound)

  bool have_packet_ = false;
  uint16_t last_counter_ = 0;
  uint64_t sequence_ = 0;
  uint32_t last_sample_time_fine_ = 0;
  int64_t device_ticks_ = 0;  // SampleTimeFine unwrapped
  Time last_stamp_;
  XsensMtiStats stats_{};
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_IMU_XSENS_MTI_DRIVER_H_
