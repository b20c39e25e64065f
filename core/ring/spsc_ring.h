#ifndef ROVER_CORE_RING_SPSC_RING_H_
#define ROVER_CORE_RING_SPSC_RING_H_

// Bounded lock-free single-producer / single-consumer ring with inline
// storage, for handing data between real-time threads (driver -> estimator,
// estimator -> flight log) without locks, heap or syscalls.
//
// Exactly one thread may call the producer functions (TryPush, TryEmplace,
// BeginPush, CommitPush, TryPushWith) and exactly one thread the consumer
// functions (TryPop, Front, PopFront). The roles may move to another thread
// only across a synchronising hand-over (mutex, thread join). The statistics
// (pushed, popped, dropped, high_water_mark, size) may be read from any
// thread; they are relaxed snapshots, exact once both sides are quiescent.
//
// Every operation is wait-free: a bounded number of steps, no retry loops.
//
// Overflow policy (template parameter, it changes the slot layout):
//
// * OverflowPolicy::kReject: a push into a full ring fails and counts one
//   drop; the queued items are untouched. Classic design: the producer owns
//   `head_`, the consumer owns `tail_`, each side caches the other's index
//   and re-reads it only when the cached value says full / empty, so in the
//   common case neither side touches the other's cache line. Supports any
//   nothrow-movable T and in-place access (BeginPush/CommitPush, Front/
//   PopFront) so large records are built and read without an extra copy.
//
// * OverflowPolicy::kOverwriteOldest: a push never fails; when the ring is
//   full the new item replaces the oldest one. The producer must not move the
//   consumer's index (that would make `tail_` a two-writer variable and race
//   with a pop in progress), so instead every slot carries a sequence stamp
//   (see seqlock_slot.h): the producer always writes slot `head % capacity`
//   and bumps the stamp; the consumer validates the stamp before and after
//   copying. If the producer lapped it, the consumer jumps to the oldest item
//   that may still be intact, counts the skipped items as dropped, and
//   retries (at most three attempts in all). Because the consumer may be
//   copying a slot while it is overwritten, items are copied word-wise
//   through relaxed atomics: T must be trivially copyable and there is no
//   in-place Front()/BeginPush().
//
// Accounting invariant (exact when quiescent, for both policies):
//   pushed() == popped() + dropped() + size()
// where pushed() counts every push call, accepted or rejected.

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>

#include "core/ring/seqlock_slot.h"

namespace rover {

/// What a push into a full ring does.
enum class OverflowPolicy {
  /// The push fails and is counted as dropped.
  kReject,
  /// The push succeeds and the oldest queued item is lost (counted in
  /// SpscRing::dropped()).
  kOverwriteOldest,
};

/// Bounded wait-free SPSC ring of `kCapacity` items of T, stored inline.
/// kCapacity must be a power of two (index wrap is a mask).
template <typename T, std::size_t kCapacity, OverflowPolicy kPolicy = OverflowPolicy::kReject>
class SpscRing {
  static_assert(kCapacity >= 1 && (kCapacity & (kCapacity - 1)) == 0,
                "SpscRing capacity must be a power of two");
  static_assert(std::is_nothrow_move_constructible_v<T> && std::is_nothrow_destructible_v<T>,
                "SpscRing items must be nothrow-movable");
  static_assert(kPolicy == OverflowPolicy::kReject || std::is_trivially_copyable_v<T>,
                "kOverwriteOldest copies items word-wise and needs a trivially copyable T");

  static constexpr bool kRejects = kPolicy == OverflowPolicy::kReject;

 public:
  using value_type = T;

  /// Number of items the ring holds.
  static constexpr std::size_t capacity() { return kCapacity; }
  /// The overflow policy of this ring type.
  static constexpr OverflowPolicy overflow_policy() { return kPolicy; }

  SpscRing() = default;
  /// Destroys the items still queued (kReject with non-trivial T).
  ~SpscRing() {
    if constexpr (kRejects && !std::is_trivially_destructible_v<T>) {
      const uint64_t head = head_.load(std::memory_order_acquire);
      for (uint64_t i = tail_.load(std::memory_order_relaxed); i != head; ++i) {
        std::destroy_at(ItemAt(i));
      }
    }
  }
  SpscRing(const SpscRing&) = delete;
  SpscRing& operator=(const SpscRing&) = delete;

  // ---------------------------------------------------------------- producer

  /// Copies `item` into the ring. kReject: returns false and counts a drop if
  /// the ring is full. kOverwriteOldest: always returns true.
  bool TryPush(const T& item) { return TryEmplace(item); }

  /// Moves `item` into the ring; same result as TryPush(const T&). On failure
  /// `item` is left untouched.
  bool TryPush(T&& item) { return TryEmplace(std::move(item)); }

  /// Constructs an item from `args` directly in the ring (kReject) or copies a
  /// temporary into it (kOverwriteOldest). Same result as TryPush.
  template <typename... Args>
  bool TryEmplace(Args&&... args) {
    const uint64_t head = head_.load(std::memory_order_relaxed);
    if constexpr (kRejects) {
      if (!HasRoomAt(head)) {
        return false;
      }
      ::new (static_cast<void*>(slots_[head & kMask].bytes)) T(std::forward<Args>(args)...);
    } else {
      SeqSlot& slot = slots_[head & kMask];
      if constexpr (sizeof...(Args) == 1 && (std::is_same_v<std::remove_cvref_t<Args>, T> && ...)) {
        // Copies straight from the caller's object, no temporary.
        ring_internal::WriteSlot(slot.stamp, slot.words, head, std::addressof(args)..., sizeof(T));
      } else {
        const T item(std::forward<Args>(args)...);
        ring_internal::WriteSlot(slot.stamp, slot.words, head, &item, sizeof(T));
      }
    }
    Publish(head);
    return true;
  }

  /// Reserves the next slot for in-place construction and returns it, already
  /// default-initialised (no zeroing for trivial types). Returns nullptr, and
  /// counts a drop, if the ring is full. A successful BeginPush must be
  /// followed by CommitPush() before the next producer call; until then the
  /// item is invisible to the consumer. Abandoning it is allowed (the slot is
  /// reused by the next push) because T is trivially destructible.
  T* BeginPush() requires(
      kRejects&& std::is_trivially_destructible_v<T>&& std::is_default_constructible_v<T>) {
    const uint64_t head = head_.load(std::memory_order_relaxed);
    if (!HasRoomAt(head)) {
      return nullptr;
    }
    return ::new (static_cast<void*>(slots_[head & kMask].bytes)) T;
  }

  /// Publishes the item reserved by the last successful BeginPush().
  void CommitPush() requires(kRejects) { Publish(head_.load(std::memory_order_relaxed)); }

  /// Hints the CPU to fetch, for writing, the first `bytes` of the slot the
  /// next push will use. A producer that pushes rarely (one record per
  /// sensor tick) calls this after CommitPush() so the next push finds its
  /// cache lines local instead of in the consumer's cache. Only a hint: it
  /// never faults, blocks or changes the ring.
  void PrefetchNextPush(std::size_t bytes) const requires(kRejects) {
    const auto* slot = slots_[head_.load(std::memory_order_relaxed) & kMask].bytes;
    const std::size_t n = std::min(bytes, sizeof(T));
    for (std::size_t offset = 0; offset < n; offset += kLine) {
      __builtin_prefetch(slot + offset, 1, 3);
    }
  }

  /// Runs `fill(T&)` on a reserved slot and publishes it: BeginPush + fill +
  /// CommitPush. Returns false (a drop is counted, `fill` is not called) if
  /// the ring is full.
  template <typename Fill>
  bool TryPushWith(Fill&& fill) requires(
      kRejects&& std::is_trivially_destructible_v<T>&& std::is_default_constructible_v<T>&&
          std::is_invocable_v<Fill&, T&>) {
    T* slot = BeginPush();
    if (slot == nullptr) {
      return false;
    }
    fill(*slot);
    CommitPush();
    return true;
  }

  // ---------------------------------------------------------------- consumer

  /// Moves the oldest item into `*out` and removes it. Returns false if the
  /// ring is empty. kOverwriteOldest: items the producer overwrote before they
  /// were read are skipped and counted as dropped; if the producer overwrites
  /// the slot being read three times in a row within this call, returns false
  /// although newer items exist (the next call resumes at the oldest intact
  /// item) and `*out` holds garbage.
  bool TryPop(T* out) {
    if constexpr (kRejects) {
      T* front = Front();
      if (front == nullptr) {
        return false;
      }
      *out = std::move(*front);
      PopFront();
      return true;
    } else {
      return TryPopOverwriting(out);
    }
  }

  /// Returns the oldest item in place, or nullptr if the ring is empty. The
  /// item stays valid and queued until PopFront().
  T* Front() requires(kRejects) {
    const uint64_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == cached_head_) {
      cached_head_ = head_.load(std::memory_order_acquire);
      if (tail == cached_head_) {
        return nullptr;
      }
    }
    return ItemAt(tail);
  }

  /// Destroys and removes the oldest item. Precondition: the last Front()
  /// call returned non-null and no pop happened since.
  void PopFront() requires(kRejects) {
    const uint64_t tail = tail_.load(std::memory_order_relaxed);
    std::destroy_at(ItemAt(tail));
    // Release: the slot (our reads of it, the destruction) must be finished
    // before the producer may reuse it.
    tail_.store(tail + 1, std::memory_order_release);
    popped_.store(popped_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  }

  // -------------------------------------------------------------- statistics

  /// Items offered to the ring since construction, accepted or rejected:
  /// each TryPush/TryEmplace/TryPushWith call, each CommitPush and each
  /// BeginPush that failed.
  uint64_t pushed() const {
    const uint64_t accepted = head_.load(std::memory_order_relaxed);
    if constexpr (kRejects) {
      return accepted + rejected_.load(std::memory_order_relaxed);
    } else {
      return accepted;
    }
  }
  /// Items handed to the consumer since construction.
  uint64_t popped() const { return popped_.load(std::memory_order_relaxed); }
  /// Items lost: rejected pushes (kReject), or overwritten items
  /// (kOverwriteOldest; includes overwritten items the consumer has not
  /// reached yet, so it is current even when the consumer stalls).
  uint64_t dropped() const {
    if constexpr (kRejects) {
      return rejected_.load(std::memory_order_relaxed);
    } else {
      const uint64_t tail = tail_.load(std::memory_order_relaxed);
      const uint64_t head = head_.load(std::memory_order_relaxed);
      const uint64_t pending = head > tail + kCapacity ? head - tail - kCapacity : 0;
      return overwritten_.load(std::memory_order_relaxed) + pending;
    }
  }
  /// Largest number of items that were queued at once, observed by the
  /// producer right after a push.
  uint64_t high_water_mark() const { return high_water_mark_.load(std::memory_order_relaxed); }
  /// Items currently queued (a snapshot when read concurrently).
  uint64_t size() const {
    const uint64_t tail = tail_.load(std::memory_order_relaxed);
    const uint64_t head = head_.load(std::memory_order_relaxed);
    return head > tail ? std::min<uint64_t>(head - tail, kCapacity) : 0;
  }
  /// True if size() == 0.
  bool empty() const { return size() == 0; }

 private:
  static constexpr uint64_t kMask = kCapacity - 1;
  static constexpr int kMaxReadAttempts = 3;
  static constexpr std::size_t kLine = ring_internal::kFalseSharingRangeBytes;

  struct RawSlot {
    alignas(T) unsigned char bytes[sizeof(T)];
  };
  struct SeqSlot {
    std::atomic<uint64_t> stamp{0};
    std::atomic<uint64_t> words[ring_internal::WordsForBytes(sizeof(T))]{};
  };
  using Slot = std::conditional_t<kRejects, RawSlot, SeqSlot>;

  T* ItemAt(uint64_t index) requires(kRejects) {
    return std::launder(reinterpret_cast<T*>(slots_[index & kMask].bytes));
  }

  // kReject producer: true if slot `head` is free, refreshing the cached tail
  // only when the cached value says full. Counts a drop when full.
  bool HasRoomAt(uint64_t head) {
    if (head - cached_tail_ >= kCapacity) {
      // Acquire: the consumer's last reads of the slot happen-before our
      // overwrite of it.
      cached_tail_ = tail_.load(std::memory_order_acquire);
      if (head - cached_tail_ >= kCapacity) {
        rejected_.store(rejected_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
        return false;
      }
    }
    return true;
  }

  // Makes item `head` visible to the consumer and updates the high-water mark.
  void Publish(uint64_t head) {
    const uint64_t new_head = head + 1;
    head_.store(new_head, std::memory_order_release);
    // The cached tail only lags, so head - cached_tail_ over-estimates the
    // fill level. Re-read the real tail only when that estimate would raise
    // the mark: once the mark reflects the usual backlog this is rare, and
    // the mark stays exact rather than drifting up to the capacity.
    if (new_head - cached_tail_ > high_water_mark_local_ && high_water_mark_local_ < kCapacity) {
      cached_tail_ = tail_.load(std::memory_order_acquire);
      const uint64_t fill = std::min<uint64_t>(new_head - cached_tail_, kCapacity);
      if (fill > high_water_mark_local_) {
        high_water_mark_local_ = fill;
        high_water_mark_.store(fill, std::memory_order_relaxed);
      }
    }
  }

  bool TryPopOverwriting(T* out) {
    uint64_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == cached_head_) {
      cached_head_ = head_.load(std::memory_order_acquire);
      if (tail == cached_head_) {
        return false;
      }
    }
    if (cached_head_ - tail > kCapacity) {
      // Items before head - capacity were certainly overwritten.
      tail = SkipTo(tail, cached_head_ - kCapacity);
    }
    // A failed attempt means the producer lapped the consumer; every retry
    // starts at the oldest item of a freshly read head, so it fails again
    // only if the producer keeps overwriting that very slot. Three attempts
    // bound the work (wait-free) and in practice never run out.
    for (int attempt = 0; attempt < kMaxReadAttempts; ++attempt) {
      const SeqSlot& slot = slots_[tail & kMask];
      if (ring_internal::ReadSlot(slot.stamp, slot.words, tail, out, sizeof(T))) {
        tail_.store(tail + 1, std::memory_order_release);
        popped_.store(popped_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
        return true;
      }
      // Items before head - capacity are gone. Item head - capacity is
      // intact unless the producer is writing item `head` into its slot right
      // now, which the next attempt detects.
      cached_head_ = head_.load(std::memory_order_acquire);
      const uint64_t oldest = cached_head_ > kCapacity ? cached_head_ - kCapacity : 0;
      tail = SkipTo(tail, std::max(tail + 1, oldest));
      if (tail >= cached_head_) {
        return false;
      }
    }
    return false;
  }

  // Consumer (kOverwriteOldest): moves the tail forward, counting the skipped
  // items as dropped. Returns the new tail.
  uint64_t SkipTo(uint64_t tail, uint64_t new_tail) {
    overwritten_.store(overwritten_.load(std::memory_order_relaxed) + (new_tail - tail),
                       std::memory_order_relaxed);
    tail_.store(new_tail, std::memory_order_release);
    return new_tail;
  }

  // Producer-owned line: written on every push. cached_tail_ and the local
  // mark are private to the producer.
  alignas(kLine) std::atomic<uint64_t> head_{0};
  uint64_t cached_tail_ = 0;
  uint64_t high_water_mark_local_ = 0;
  std::atomic<uint64_t> rejected_{0};
  std::atomic<uint64_t> high_water_mark_{0};

  // Consumer-owned line. In kOverwriteOldest mode the producer never reads
  // tail_ for correctness, only for the high-water mark.
  alignas(kLine) std::atomic<uint64_t> tail_{0};
  uint64_t cached_head_ = 0;
  std::atomic<uint64_t> popped_{0};
  std::atomic<uint64_t> overwritten_{0};

  alignas(kLine) Slot slots_[kCapacity];
};

}  // namespace rover

#endif  // ROVER_CORE_RING_SPSC_RING_H_
