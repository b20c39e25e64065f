#include "core/ring/broadcast_ring.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include "core/ring/seqlock_slot.h"

namespace rover {
namespace {

// Slots are padded to whole 64-byte lines so a reader copying one record does
// not share a line with the slot the writer is filling.
constexpr std::size_t kWordsPerLine = 64 / sizeof(uint64_t);

}  // namespace

BroadcastRing::BroadcastRing(std::size_t record_size_bytes, std::size_t capacity_records)
    : record_size_bytes_(record_size_bytes), capacity_(capacity_records) {
  if (record_size_bytes == 0 || capacity_records < 2 ||
      (capacity_records & (capacity_records - 1)) != 0) {
    std::fprintf(stderr, "BroadcastRing: invalid record size %zu or capacity %zu\n",
                 record_size_bytes, capacity_records);
    std::abort();
  }
  const std::size_t words = 1 + ring_internal::WordsForBytes(record_size_bytes);
  slot_stride_words_ = (words + kWordsPerLine - 1) / kWordsPerLine * kWordsPerLine;
  // Value-initialised: every stamp starts at 0, which matches no record.
  words_ = std::make_unique<std::atomic<uint64_t>[]>(slot_stride_words_ * capacity_);
}

std::atomic<uint64_t>* BroadcastRing::SlotAt(uint64_t index) const {
  return &words_[(index & (capacity_ - 1)) * slot_stride_words_];
}

void BroadcastRing::Write(const void* record) {
  const uint64_t index = head_.load(std::memory_order_relaxed);
  std::atomic<uint64_t>* slot = SlotAt(index);
  ring_internal::WriteSlot(slot[0], slot + 1, index, record, record_size_bytes_);
  head_.store(index + 1, std::memory_order_release);
}

BroadcastRing::Cursor BroadcastRing::MakeCursor(uint64_t backlog_records) const {
  const uint64_t head = write_count();
  const uint64_t backlog = std::min<uint64_t>({backlog_records, capacity_ - 1, head});
  return Cursor{head - backlog};
}

bool BroadcastRing::ReadNext(Cursor* cursor, uint64_t window_records, void* out,
                             uint64_t* skipped_records) const {
  const uint64_t window = std::clamp<uint64_t>(window_records, 1, capacity_ - 1);
  uint64_t head = write_count();
  for (int attempt = 0; attempt < 2; ++attempt) {
    if (cursor->next_index >= head) {
      return false;
    }
    if (head - cursor->next_index > window) {
      *skipped_records += head - window - cursor->next_index;
      cursor->next_index = head - window;
    }
    const std::atomic<uint64_t>* slot = SlotAt(cursor->next_index);
    if (ring_internal::ReadSlot(slot[0], slot + 1, cursor->next_index, out, record_size_bytes_)) {
      ++cursor->next_index;
      return true;
    }
    // Lapped during the copy: the writer has started record
    // next_index + capacity, so the fresh head moves the window past it.
    head = write_count();
  }
  return false;
}

}  // namespace rover
