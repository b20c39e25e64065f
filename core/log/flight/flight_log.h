#ifndef ROVER_CORE_LOG_FLIGHT_FLIGHT_LOG_H_
#define ROVER_CORE_LOG_FLIGHT_FLIGHT_LOG_H_

// The flight log: a crash-safe MCAP file fed by real-time producers.
//
//   producer threads ──LogChannel::Log()──► SPSC rings ──writer thread──► McapWriter ──► file
//
// Set-up (Open, AddChannel) allocates and happens before Start(). After
// Start(), producers only touch their own ring. The writer thread wakes every
// `drain_period`, drains all rings and, every `health_period`, writes a
// rover_msgs/msg/LogHealth record with each channel's written and dropped
// counts, so losses are visible in the log itself. Stop() drains what is
// left, writes a final LogHealth and closes the file with its summary.

#include <condition_variable>
#include <exception>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "core/log/flight/log_channel.h"
#include "core/log/mcap/mcap_writer.h"
#include "core/log/msgs/rover_msgs.h"
#include "core/time/time.h"

namespace rover::log {

struct FlightLogOptions {
  McapWriterOptions mcap;
  Duration drain_period = Duration::Milliseconds(5);
  Duration health_period = Duration::Seconds(1);
  std::string health_topic = "/rover/log_health";
  /// Log time of the LogHealth records (called on the writer thread). Empty:
  /// CLOCK_MONOTONIC. A simulation in lockstep, whose data carry simulated
  /// time, passes its newest sensor time so that the health records sit
  /// among the data they describe; a record is skipped while it returns
  /// Time::Zero() (no data yet).
  std::function<Time()> record_clock;
};

/// Totals over all channels, for summaries and tests.
struct FlightLogStats {
  uint64_t logged = 0;
  uint64_t written = 0;
  uint64_t dropped = 0;  ///< full ring or oversize, all channels
  McapStats mcap;
  std::string error;  ///< first writer error (disk full, I/O error), empty if none
};

class FlightLog {
 public:
  explicit FlightLog(FlightLogOptions options = {});
  ~FlightLog();  ///< stops and closes if still running
  FlightLog(const FlightLog&) = delete;
  FlightLog& operator=(const FlightLog&) = delete;

  /// Creates the MCAP file. Throws McapError naming the path on failure.
  void Open(const std::string& path);

  /// Registers a channel for `Msg` on `topic` (schema added once per type).
  /// Call after Open() and before Start(). The returned handle lives as long
  /// as the FlightLog; one thread may log through it.
  template <RosMessage Msg, std::size_t kSlotBytes = 1024, std::size_t kSlots = 1024>
  LogChannel<Msg, kSlotBytes, kSlots>* AddChannel(const std::string& topic) {
    const uint16_t schema_id =
        SchemaFor(MessageTraits<Msg>::kName, MessageTraits<Msg>::Definition());
    auto channel = std::make_unique<LogChannel<Msg, kSlotBytes, kSlots>>(
        topic, writer_.AddChannel(schema_id, topic, kCdrMessageEncoding));
    auto* handle = channel.get();
    channels_.push_back(std::move(channel));
    return handle;
  }

  /// Writes a metadata record (e.g. the board config, the software version).
  void WriteMetadata(const std::string& name, const std::map<std::string, std::string>& values);

  /// Starts the writer thread. After this, only LogChannel::Log() is allowed
  /// until Stop().
  void Start();

  /// Drains every ring, writes the final LogHealth and closes the file.
  /// Idempotent.
  void Stop();

  /// Totals so far; callable from any thread.
  FlightLogStats stats() const;

 private:
  uint16_t SchemaFor(std::string_view name, std::string_view definition);
  void Run();
  void DrainAll();
  void FlushChunk();
  void RecordError(const std::exception& e);
  void WriteHealth(Time now);

  FlightLogOptions options_;
  McapWriter writer_;
  std::vector<std::unique_ptr<LogChannelBase>> channels_;
  std::map<std::string, uint16_t, std::less<>> schema_ids_;
  uint16_t health_channel_id_ = 0;
  uint32_t health_sequence_ = 0;
  std::vector<std::byte> health_buffer_;
  rover_msgs::LogHealth health_msg_;

  std::thread thread_;
  std::mutex wake_mutex_;
  std::condition_variable wake_;
  bool stop_requested_ = false;  // guarded by wake_mutex_
  bool started_ = false;
  bool closed_ = false;
  mutable std::mutex stats_mutex_;  // guards error_ and mcap_stats_ (writer thread <-> readers)
  std::string error_;
  McapStats mcap_stats_;
};

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_FLIGHT_FLIGHT_LOG_H_
