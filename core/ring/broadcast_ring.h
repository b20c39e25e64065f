#ifndef ROVER_CORE_RING_BROADCAST_RING_H_
#define ROVER_CORE_RING_BROADCAST_RING_H_

// Lossy single-writer / multi-reader broadcast ring of fixed-size byte
// records, sized at run time. Each reader keeps its own Cursor, so any number
// of readers see every record without the writer knowing about them; a reader
// that falls behind loses the oldest records (the writer never waits).
//
// This is the queue behind the in-process IPC transport: one ring per topic,
// one cursor per subscriber, and a subscriber's "queue capacity" is the
// window of newest records its cursor may lag behind.
//
// Correctness: the writer overwrites slots without looking at readers, so
// slots are seqlocks (see seqlock_slot.h) and a reader validates every copy;
// a copy the writer lapped is discarded and counted as skipped.
//
// Thread safety: one writer thread at a time (moving the writer role needs a
// synchronising hand-over such as a mutex). Each Cursor belongs to one reader
// thread. Any number of readers may run concurrently with the writer.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>

namespace rover {

class BroadcastRing {
 public:
  /// Position of a reader: index of the next record it will read.
  struct Cursor {
    uint64_t next_index = 0;
  };

  /// Allocates `capacity_records` slots of `record_size_bytes` each (the only
  /// allocation). Requires record_size_bytes > 0 and capacity_records a power
  /// of two >= 2; aborts otherwise, since these are programming errors.
  BroadcastRing(std::size_t record_size_bytes, std::size_t capacity_records);
  BroadcastRing(const BroadcastRing&) = delete;
  BroadcastRing& operator=(const BroadcastRing&) = delete;

  /// Size of every record in bytes.
  std::size_t record_size_bytes() const { return record_size_bytes_; }
  /// Number of slots. A reader can lag at most capacity() - 1 records: the
  /// slot of the oldest record is the one the writer overwrites next.
  std::size_t capacity() const { return capacity_; }

  /// Writer: appends `record_size_bytes()` bytes from `record`, overwriting
  /// the oldest record if needed. Wait-free, never allocates.
  void Write(const void* record);

  /// Number of records written since construction. Any thread.
  uint64_t write_count() const { return head_.load(std::memory_order_acquire); }

  /// Reader: returns a cursor positioned so that the next reads return the
  /// newest min(backlog_records, capacity() - 1, write_count()) records
  /// already written, then everything written later.
  Cursor MakeCursor(uint64_t backlog_records) const;

  /// Reader: copies the oldest unread record among the newest
  /// `window_records` records (clamped to [1, capacity() - 1]) into `out` and
  /// advances the cursor. Returns false if there is no such record. Adds the
  /// number of records the cursor skipped (older than the window, or lapped
  /// by the writer during the copy) to `*skipped_records`. Wait-free: at most
  /// two copy attempts; it returns false with unread records left only if
  /// the writer overwrote a whole ring's worth of records during the call.
  bool ReadNext(Cursor* cursor, uint64_t window_records, void* out,
                uint64_t* skipped_records) const;

 private:
  std::atomic<uint64_t>* SlotAt(uint64_t index) const;

  std::size_t record_size_bytes_;
  std::size_t capacity_;
  std::size_t slot_stride_words_;  // stamp word + record words, padded
  std::unique_ptr<std::atomic<uint64_t>[]> words_;
  alignas(128) std::atomic<uint64_t> head_{0};
};

}  // namespace rover

#endif  // ROVER_CORE_RING_BROADCAST_RING_H_
