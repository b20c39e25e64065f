#include "core/log/flight/flight_log.h"

#include <chrono>
#include <exception>

namespace rover::log {
namespace {

// Records drained from one ring per pass, so a busy channel cannot starve
// the others of writer time.
constexpr std::size_t kMaxRecordsPerPass = 4096;

std::span<const std::byte> AsBytes(std::string_view s) {
  return {reinterpret_cast<const std::byte*>(s.data()), s.size()};
}

}  // namespace

FlightLog::FlightLog(FlightLogOptions options)
    : options_(std::move(options)), writer_(options_.mcap) {}

FlightLog::~FlightLog() {
  try {
    Stop();
  } catch (...) {  // a destructor must not throw; Stop() records the error
  }
}

void FlightLog::Open(const std::string& path) {
  writer_.Open(path);
  const uint16_t schema = SchemaFor(MessageTraits<rover_msgs::LogHealth>::kName,
                                    MessageTraits<rover_msgs::LogHealth>::Definition());
  health_channel_id_ = writer_.AddChannel(schema, options_.health_topic, kCdrMessageEncoding);
}

uint16_t FlightLog::SchemaFor(std::string_view name, std::string_view definition) {
  if (const auto it = schema_ids_.find(name); it != schema_ids_.end()) return it->second;
  const uint16_t id = writer_.AddSchema(name, kRos2MsgSchemaEncoding, AsBytes(definition));
  schema_ids_.emplace(std::string(name), id);
  return id;
}

void FlightLog::WriteMetadata(const std::string& name,
                              const std::map<std::string, std::string>& values) {
  writer_.WriteMetadata(name, values);
}

void FlightLog::Start() {
  if (started_) return;
  // Size the health message once, so the writer thread reuses its storage.
  health_msg_.channels.resize(channels_.size());
  for (std::size_t i = 0; i < channels_.size(); ++i) {
    health_msg_.channels[i].topic = channels_[i]->topic();
  }
  health_msg_.header.frame_id = "flight_log";
  started_ = true;
  thread_ = std::thread([this] { Run(); });
}

void FlightLog::Run() {
  Time next_health = Time::Now() + options_.health_period;
  Time last_chunk_flush = Time::Now();
  const Duration max_chunk_age = Duration::Nanoseconds(options_.mcap.max_chunk_duration_ns);
  for (;;) {
    {
      // Only the writer thread and Stop() use this lock; producers never do.
      std::unique_lock lock(wake_mutex_);
      wake_.wait_for(lock, std::chrono::nanoseconds(options_.drain_period.nanoseconds()),
                     [this] { return stop_requested_; });
      if (stop_requested_) return;
    }
    DrainAll();
    const Time now = Time::Now();
    if (now - last_chunk_flush >= max_chunk_age) {
      // The MCAP writer closes a chunk by age only when a message arrives;
      // when producers go quiet, close it here so power loss cannot take
      // more than one chunk period of data with it.
      FlushChunk();
      last_chunk_flush = now;
    }
    if (now >= next_health) {
      WriteHealth(now);
      next_health = now + options_.health_period;
    }
  }
}

void FlightLog::DrainAll() {
  try {
    bool more = true;
    while (more) {
      more = false;
      for (auto& channel : channels_) {
        more |= channel->DrainInto(writer_, kMaxRecordsPerPass) == kMaxRecordsPerPass;
      }
    }
  } catch (const std::exception& e) {
    // The file is unusable past this point (disk full, I/O error); producers
    // keep running and their losses keep being counted.
    RecordError(e);
  }
  std::lock_guard lock(stats_mutex_);
  mcap_stats_ = writer_.stats();
}

void FlightLog::RecordError(const std::exception& e) {
  std::lock_guard lock(stats_mutex_);
  if (error_.empty()) error_ = e.what();  // the first error explains the rest
}

void FlightLog::FlushChunk() {
  try {
    writer_.FlushChunk();
  } catch (const std::exception& e) {
    RecordError(e);
  }
}

void FlightLog::WriteHealth(Time wall_now) {
  const Time now = options_.record_clock ? options_.record_clock() : wall_now;
  if (now == Time::Zero()) return;
  health_msg_.header.stamp = ToRosTime(now);
  uint64_t written = 0;
  for (std::size_t i = 0; i < channels_.size(); ++i) {
    const LogChannelCounters c = channels_[i]->counters();
    auto& entry = health_msg_.channels[i];
    entry.records_written = c.written;
    entry.records_dropped = c.dropped_full + c.dropped_oversize;
    entry.ring_high_water = static_cast<uint32_t>(c.ring_high_water);
    written += c.written;
  }
  health_msg_.records_written = written;
  health_msg_.bytes_written = writer_.stats().bytes_written;
  health_buffer_.clear();
  CdrWriter cdr(&health_buffer_);
  Serialize(health_msg_, cdr);
  try {
    const auto t = static_cast<uint64_t>(now.nanoseconds());
    writer_.WriteMessage(health_channel_id_, health_sequence_++, t, t, health_buffer_);
  } catch (const std::exception& e) {
    RecordError(e);
  }
}

void FlightLog::Stop() {
  if (closed_) return;
  closed_ = true;
  if (started_) {
    {
      std::lock_guard lock(wake_mutex_);
      stop_requested_ = true;
    }
    wake_.notify_one();
    thread_.join();
    DrainAll();
    WriteHealth(Time::Now());
  }
  if (writer_.is_open()) {
    try {
      writer_.Close();
    } catch (const std::exception& e) {
      RecordError(e);
    }
  }
  std::lock_guard lock(stats_mutex_);
  mcap_stats_ = writer_.stats();
}

FlightLogStats FlightLog::stats() const {
  FlightLogStats s;
  for (const auto& channel : channels_) {
    const LogChannelCounters c = channel->counters();
    s.logged += c.logged;
    s.written += c.written;
    s.dropped += c.dropped_full + c.dropped_oversize;
  }
  std::lock_guard lock(stats_mutex_);
  s.mcap = mcap_stats_;
  s.error = error_;
  return s;
}

}  // namespace rover::log
