#ifndef ROVER_CORE_LOG_FLIGHT_LOG_CHANNEL_H_
#define ROVER_CORE_LOG_FLIGHT_LOG_CHANNEL_H_

// The real-time side of the flight log: one LogChannel per topic and
// producer thread. Log() serialises the message straight into a slot of a
// lock-free SPSC ring; the FlightLog writer thread drains the ring into the
// MCAP file. Log() never blocks, never allocates and never makes a syscall,
// so it may be called from the IMU loop. A full ring or an oversized message
// is a counted drop, reported in the log itself (rover_msgs/msg/LogHealth).

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>

#include "core/log/mcap/mcap_writer.h"
#include "core/log/msgs/message_traits.h"
#include "core/ring/spsc_ring.h"
#include "core/time/time.h"

namespace rover::log {

/// Counters of one channel; safe to read from any thread (relaxed snapshot).
struct LogChannelCounters {
  uint64_t logged = 0;            ///< Log() calls
  uint64_t written = 0;           ///< records handed to the MCAP writer
  uint64_t dropped_full = 0;      ///< rejected because the ring was full
  uint64_t dropped_oversize = 0;  ///< rejected because the serialised message exceeded a slot
  uint64_t ring_high_water = 0;   ///< most records ever queued at once
};

/// Type-erased view of a channel, used by the writer thread.
class LogChannelBase {
 public:
  LogChannelBase(std::string topic, uint16_t mcap_channel_id)
      : topic_(std::move(topic)), mcap_channel_id_(mcap_channel_id) {}
  virtual ~LogChannelBase() = default;
  LogChannelBase(const LogChannelBase&) = delete;
  LogChannelBase& operator=(const LogChannelBase&) = delete;

  const std::string& topic() const { return topic_; }
  uint16_t mcap_channel_id() const { return mcap_channel_id_; }

  /// Consumer side: moves up to `max_records` queued records into `writer`.
  /// Returns how many were written. Only the writer thread calls this.
  virtual std::size_t DrainInto(McapWriter& writer, std::size_t max_records) = 0;
  virtual LogChannelCounters counters() const = 0;

 private:
  std::string topic_;
  uint16_t mcap_channel_id_;
};

/// A serialised message as it crosses the ring.
template <std::size_t kPayloadBytes>
struct LogRecord {
  int64_t log_time_ns;
  uint32_t sequence;
  uint32_t size;
  std::array<std::byte, kPayloadBytes> payload;
};

/// Real-time producer handle for messages of type `Msg`. `kSlotBytes` bounds
/// the serialised size (CDR, including its 4-byte header); `kSlots` is the
/// ring depth (a power of two). Exactly one thread may call Log().
template <RosMessage Msg, std::size_t kSlotBytes = 1024, std::size_t kSlots = 1024>
class LogChannel final : public LogChannelBase {
 public:
  using Record = LogRecord<kSlotBytes>;
  using Ring = SpscRing<Record, kSlots, OverflowPolicy::kReject>;

  LogChannel(std::string topic, uint16_t mcap_channel_id)
      : LogChannelBase(std::move(topic), mcap_channel_id) {}

  /// Queues `msg` stamped `log_time`. Wait-free; returns false (and counts a
  /// drop) if the ring is full or the message does not fit in a slot.
  bool Log(Time log_time, const Msg& msg) {
    const uint32_t sequence = next_sequence_++;
    logged_.store(logged_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
    Record* slot = ring_.BeginPush();
    if (slot == nullptr) return false;  // the ring counts this drop
    // Serialise into a cache-hot scratch buffer, then copy with wide stores:
    // the slot's lines are usually in the writer thread's cache, and a few
    // vector stores stall far less on them than dozens of field stores.
    CdrWriter writer{std::span<std::byte>(scratch_)};
    Serialize(msg, writer);
    if (!writer.ok()) {
      // Abandoned slots are reused by the next push (trivially destructible).
      dropped_oversize_.store(dropped_oversize_.load(std::memory_order_relaxed) + 1,
                              std::memory_order_relaxed);
      return false;
    }
    std::memcpy(slot->payload.data(), scratch_.data(), writer.size());
    slot->log_time_ns = log_time.nanoseconds();
    slot->sequence = sequence;
    slot->size = static_cast<uint32_t>(writer.size());
    ring_.CommitPush();
    // Records of one channel have about the same size; warm the next slot
    // now so the next call does not pay the cache misses.
    ring_.PrefetchNextPush(offsetof(Record, payload) + writer.size());
    return true;
  }

  std::size_t DrainInto(McapWriter& writer, std::size_t max_records) override {
    std::size_t n = 0;
    for (; n < max_records; ++n) {
      const Record* record = ring_.Front();
      if (record == nullptr) break;
      const auto t = static_cast<uint64_t>(record->log_time_ns);
      writer.WriteMessage(mcap_channel_id(), record->sequence, t, t,
                          std::span<const std::byte>(record->payload.data(), record->size));
      ring_.PopFront();
    }
    return n;
  }

  /// Records queued and not yet written (any thread; exact for the producer).
  std::size_t queued() const { return static_cast<std::size_t>(ring_.size()); }
  static constexpr std::size_t capacity() { return kSlots; }

  LogChannelCounters counters() const override {
    LogChannelCounters c;
    c.logged = logged_.load(std::memory_order_relaxed);
    c.written = ring_.popped();
    c.dropped_full = ring_.dropped();
    c.dropped_oversize = dropped_oversize_.load(std::memory_order_relaxed);
    c.ring_high_water = ring_.high_water_mark();
    return c;
  }

 private:
  Ring ring_;
  std::array<std::byte, kSlotBytes> scratch_;  // producer-owned serialisation buffer
  uint32_t next_sequence_ = 0;                 // producer-owned; gaps in the file mark drops
  std::atomic<uint64_t> logged_{0};
  std::atomic<uint64_t> dropped_oversize_{0};
};

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_FLIGHT_LOG_CHANNEL_H_
