#ifndef ROVER_CORE_RING_SEQLOCK_SLOT_H_
#define ROVER_CORE_RING_SEQLOCK_SLOT_H_

// Building blocks for lossy rings where the single writer may overwrite a
// slot while a reader is copying it (SpscRing<..., kOverwriteOldest> and
// BroadcastRing). Internal to core/ring; use the ring classes instead.
//
// Each slot is a sequence stamp plus the record stored as 64-bit words. For
// record index i the writer stores WritingStamp(i) (odd), then the words, then
// DoneStamp(i) (even). A reader that loaded DoneStamp(i) before copying and
// still sees it after copying got an untorn copy of record i; anything else
// means the writer lapped it.
//
// Why the words are atomics: a reader may copy a slot concurrently with the
// writer overwriting it. With plain memory that is a data race (undefined
// behaviour, and ThreadSanitizer rightly reports it) even though the torn copy
// is discarded. Atomic word accesses make the race defined.
//
// Ordering (after H.-J. Boehm, "Can seqlocks get along with programming
// language memory models?", MSPC 2012): the writer stores the words with
// release and the reader loads them with acquire. So if the reader sees any
// word of a newer record, the writer's earlier odd stamp happens-before the
// reader's re-check, which therefore cannot see the old stamp. The usual
// alternative, relaxed words plus standalone fences, is not understood by
// ThreadSanitizer (GCC rejects it under -fsanitize=thread); per-word
// acquire/release is what TSan checks and costs nothing on x86-64, where both
// are plain moves (AArch64 uses ldar/stlr).

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace rover::ring_internal {

/// Distance that keeps two hot variables from sharing a cache line, including
/// the adjacent-line prefetcher of x86 (which pulls 128-byte pairs). A fixed
/// constant rather than std::hardware_destructive_interference_size, whose
/// value GCC warns may change between compiler versions (an ABI hazard).
inline constexpr std::size_t kFalseSharingRangeBytes = 128;

/// Number of 64-bit words that hold a record of `size_bytes` bytes.
constexpr std::size_t WordsForBytes(std::size_t size_bytes) {
  return (size_bytes + sizeof(uint64_t) - 1) / sizeof(uint64_t);
}

/// Stamp a slot carries while record `index` is being written into it.
constexpr uint64_t WritingStamp(uint64_t index) { return 2 * index + 1; }
/// Stamp a slot carries once record `index` is completely written. The
/// initial stamp 0 never matches a record.
constexpr uint64_t DoneStamp(uint64_t index) { return 2 * index + 2; }

/// Copies `size_bytes` bytes from `src` into `words` with release stores.
/// The trailing partial word is zero-padded.
inline void StoreWords(std::atomic<uint64_t>* words, const void* src, std::size_t size_bytes) {
  const auto* bytes = static_cast<const unsigned char*>(src);
  const std::size_t full_words = size_bytes / sizeof(uint64_t);
  for (std::size_t i = 0; i < full_words; ++i) {
    uint64_t word;
    std::memcpy(&word, bytes + i * sizeof(uint64_t), sizeof(word));
    words[i].store(word, std::memory_order_release);
  }
  const std::size_t tail_bytes = size_bytes % sizeof(uint64_t);
  if (tail_bytes != 0) {
    uint64_t word = 0;
    std::memcpy(&word, bytes + full_words * sizeof(uint64_t), tail_bytes);
    words[full_words].store(word, std::memory_order_release);
  }
}

/// Copies `size_bytes` bytes out of `words` into `dst` with acquire loads.
inline void LoadWords(const std::atomic<uint64_t>* words, void* dst, std::size_t size_bytes) {
  auto* bytes = static_cast<unsigned char*>(dst);
  const std::size_t full_words = size_bytes / sizeof(uint64_t);
  for (std::size_t i = 0; i < full_words; ++i) {
    const uint64_t word = words[i].load(std::memory_order_acquire);
    std::memcpy(bytes + i * sizeof(uint64_t), &word, sizeof(word));
  }
  const std::size_t tail_bytes = size_bytes % sizeof(uint64_t);
  if (tail_bytes != 0) {
    const uint64_t word = words[full_words].load(std::memory_order_acquire);
    std::memcpy(bytes + full_words * sizeof(uint64_t), &word, tail_bytes);
  }
}

/// Writer side: stores record `index` (`size_bytes` bytes at `src`) into the
/// slot made of `stamp` and `words`. Wait-free.
inline void WriteSlot(std::atomic<uint64_t>& stamp, std::atomic<uint64_t>* words, uint64_t index,
                      const void* src, std::size_t size_bytes) {
  stamp.store(WritingStamp(index), std::memory_order_relaxed);
  // Release word stores keep the odd stamp before every new word.
  StoreWords(words, src, size_bytes);
  stamp.store(DoneStamp(index), std::memory_order_release);
}

/// Reader side: copies record `index` out of the slot into `dst`. Returns
/// true if the copy is record `index`, untorn. Returns false if the slot holds
/// (or is being overwritten with) a different record; `dst` then holds
/// garbage. Precondition: record `index` has been published (the caller saw
/// the writer's index pass it), so the slot can only be newer, never older.
inline bool ReadSlot(const std::atomic<uint64_t>& stamp, const std::atomic<uint64_t>* words,
                     uint64_t index, void* dst, std::size_t size_bytes) {
  const uint64_t before = stamp.load(std::memory_order_acquire);
  if (before != DoneStamp(index)) {
    return false;
  }
  // Acquire word loads keep the re-check after them.
  LoadWords(words, dst, size_bytes);
  return stamp.load(std::memory_order_relaxed) == before;
}

}  // namespace rover::ring_internal

#endif  // ROVER_CORE_RING_SEQLOCK_SLOT_H_
