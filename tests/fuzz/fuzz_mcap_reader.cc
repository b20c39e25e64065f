// libFuzzer target: the MCAP reader must survive any input. It may throw
// McapError only from Open() (no magic / no complete Header), must never
// crash, read out of bounds or allocate without bound, and Verify() must
// never throw at all.

#include <cstddef>
#include <cstdint>
#include <span>

#include "core/log/mcap/mcap_reader.h"

namespace {

// Keeps the optimiser from discarding reads of the delivered bytes, so ASan
// sees every byte the reader hands out.
volatile uint64_t g_sink = 0;

bool Consume(const rover::log::MessageView& m) {
  uint64_t sum = m.channel_id + m.sequence + m.log_time + m.publish_time;
  for (const std::byte b : m.data) sum += static_cast<uint64_t>(b);
  g_sink = g_sink + sum;
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto bytes = std::as_bytes(std::span(data, size));
  try {
    rover::log::McapReader reader = rover::log::McapReader::Open(bytes);
    reader.ForEachMessage(Consume);
    rover::log::ReadOptions by_time;
    by_time.order = rover::log::ReadOptions::Order::kLogTime;
    reader.ForEachMessage(Consume, by_time);
    for (const rover::log::AttachmentInfo& info : reader.attachments()) {
      if (const auto attachment = reader.ReadAttachment(info)) g_sink = g_sink + attachment->size();
    }
    g_sink = g_sink + reader.damage().size() + reader.chunks().size();
  } catch (const rover::log::McapError&) {
    // Not an MCAP file (bad magic or header): an expected outcome.
  }
  const rover::log::VerifyReport report = rover::log::Verify(bytes);  // Must not throw.
  g_sink = g_sink + report.damage.size() + report.message_count;
  return 0;
}
