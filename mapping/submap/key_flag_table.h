#ifndef ROVER_MAPPING_SUBMAP_KEY_FLAG_TABLE_H_
#define ROVER_MAPPING_SUBMAP_KEY_FLAG_TABLE_H_

// The per-image voxel set of the fast octree insertion: an open-addressing
// hash table (linear probing, load <= 1/2) from a packed 48-bit OctoMap key
// to 8 flag bits (and a 32-bit value beside). One 64-bit word per slot holds [generation:8 |
// flags:8 | key:48]; a slot whose generation is not the current one is empty, so Clear() is O(1)
// and the table is reused across images without freeing or clearing memory (only every 255th
// Clear() rewrites the array, when the generation wraps). It grows while warming up and then keeps
// its capacity: no allocation per image in steady state. std::unordered_set, as OctoMap's KeySet
// uses, allocates a node per key, which is most of the stock cost.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace rover::mapping {

class KeyFlagTable {
 public:
  static constexpr uint64_t kKeyMask = (uint64_t{1} << 48) - 1;

  /// `initial_capacity` is rounded up to a power of two (at least 64).
  explicit KeyFlagTable(std::size_t initial_capacity = std::size_t{1} << 16) {
    std::size_t capacity = 64;
    while (capacity < initial_capacity) capacity *= 2;
    Allocate(capacity);
  }

  /// Forgets every key (O(1) but for one pass per 255 calls).
  void Clear() {
    size_ = 0;
    if (++generation_ == 0) {
      // Wrapped: stale slots could carry the new generation; wipe them.
      std::fill(slots_.begin(), slots_.end(), uint64_t{0});
      generation_ = 1;
    }
  }

  /// ORs `flags` into the flags of `key` (< 2^48), inserting the key with
  /// `flags` if absent. Returns the flags it had before (0 if absent).
  uint8_t Or(uint64_t key, uint8_t flags) { return OrAt(key, flags).before; }

  /// Or() that also tells where the key lives, for value(): the slot stays
  /// valid until the next insertion of a new key.
  struct Slot {
    uint8_t before = 0;
    std::size_t index = 0;
  };
  Slot OrAt(uint64_t key, uint8_t flags) {
    if (2 * (size_ + 1) > slots_.size()) Grow();
    const uint64_t tag = uint64_t{generation_} << 56;
    for (std::size_t i = Home(key);; i = (i + 1) & mask_) {
      const uint64_t s = slots_[i];
      if ((s >> 56) != uint64_t{generation_}) {
        slots_[i] = tag | (uint64_t{flags} << 48) | key;
        values_[i] = 0;
        ++size_;
        return {0, i};
      }
      if ((s & kKeyMask) == key) {
        slots_[i] = s | (uint64_t{flags} << 48);
        return {static_cast<uint8_t>(s >> 48), i};
      }
    }
  }

  /// A 32-bit value per key for the caller (0 when the key is inserted).
  uint32_t& value(std::size_t slot) { return values_[slot]; }

  /// The flags of `key`, 0 if absent.
  uint8_t Get(uint64_t key) const {
    for (std::size_t i = Home(key);; i = (i + 1) & mask_) {
      const uint64_t s = slots_[i];
      if ((s >> 56) != uint64_t{generation_}) return 0;
      if ((s & kKeyMask) == key) return static_cast<uint8_t>(s >> 48);
    }
  }

  /// Calls f(key, flags) for every key, in table order (not sorted).
  template <typename F>
  void ForEach(F&& f) const {
    for (const uint64_t s : slots_) {
      if ((s >> 56) == uint64_t{generation_}) f(s & kKeyMask, static_cast<uint8_t>(s >> 48));
    }
  }

  /// Keys since the last Clear().
  std::size_t size() const { return size_; }
  /// Slots; stays put once the table has grown to the images' size.
  std::size_t capacity() const { return slots_.size(); }

 private:
  std::size_t Home(uint64_t key) const {
    // Fibonacci hashing: the top bits of key * 2^64 / phi spread the
    // neighbouring keys of a ray over the table.
    return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> shift_);
  }

  void Allocate(std::size_t capacity) {
    slots_.assign(capacity, uint64_t{0});
    values_.assign(capacity, 0u);
    mask_ = capacity - 1;
    shift_ = 64;
    for (std::size_t c = capacity; c > 1; c /= 2) --shift_;
  }

  void Grow() {
    std::vector<uint64_t> old;
    std::vector<uint32_t> old_values;
    old.swap(slots_);
    old_values.swap(values_);
    const uint8_t generation = generation_;
    Allocate(old.size() * 2);
    for (std::size_t j = 0; j < old.size(); ++j) {
      if ((old[j] >> 56) != uint64_t{generation}) continue;
      std::size_t i = Home(old[j] & kKeyMask);
      while ((slots_[i] >> 56) == uint64_t{generation}) i = (i + 1) & mask_;
      slots_[i] = old[j];
      values_[i] = old_values[j];
    }
  }

  std::vector<uint64_t> slots_;
  std::vector<uint32_t> values_;
  std::size_t mask_ = 0;
  int shift_ = 64;
  std::size_t size_ = 0;
  uint8_t generation_ = 1;
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_SUBMAP_KEY_FLAG_TABLE_H_
