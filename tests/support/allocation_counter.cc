#include "tests/support/allocation_counter.h"

#include <atomic>
#include <cstddef>
#include <cstdlib>
#include <new>

// Replacement global allocation functions ([new.delete] in the standard).
// Every form is replaced, including nothrow, aligned and sized deletes, so no
// allocation can bypass the counters by picking a form we forgot.

namespace {

// Plain integers (not objects with constructors) so the thread_local needs no
// dynamic initialisation: operator new may run before or during thread setup,
// when a lazily constructed thread_local would recurse into operator new.
thread_local uint64_t t_allocations = 0;
thread_local uint64_t t_deallocations = 0;
thread_local uint64_t t_allocated_bytes = 0;
std::atomic<uint64_t> g_process_allocations{0};

void CountAllocation(std::size_t size_bytes) {
  ++t_allocations;
  t_allocated_bytes += size_bytes;
  g_process_allocations.fetch_add(1, std::memory_order_relaxed);
}

void CountDeallocation(void* ptr) {
  if (ptr != nullptr) {
    ++t_deallocations;
  }
}

// Returns nullptr only once the installed new_handler gives up, as the
// standard requires of the nothrow forms.
void* AllocateOrNull(std::size_t size_bytes, std::size_t alignment_bytes) {
  // malloc(0) may return nullptr, but operator new(0) must return a unique
  // non-null pointer.
  const std::size_t size = size_bytes == 0 ? 1 : size_bytes;
  for (;;) {
    void* ptr = nullptr;
    if (alignment_bytes <= alignof(std::max_align_t)) {
      ptr = std::malloc(size);
    } else if (posix_memalign(&ptr, alignment_bytes, size) != 0) {
      ptr = nullptr;
    }
    if (ptr != nullptr) {
      CountAllocation(size_bytes);
      return ptr;
    }
    std::new_handler handler = std::get_new_handler();
    if (handler == nullptr) {
      return nullptr;
    }
    handler();  // May throw std::bad_alloc, free memory, or terminate.
  }
}

void* AllocateOrThrow(std::size_t size_bytes, std::size_t alignment_bytes) {
  void* ptr = AllocateOrNull(size_bytes, alignment_bytes);
  if (ptr == nullptr) {
    throw std::bad_alloc();
  }
  return ptr;
}

void* AllocateNoThrow(std::size_t size_bytes, std::size_t alignment_bytes) noexcept {
  try {
    return AllocateOrNull(size_bytes, alignment_bytes);
  } catch (...) {
    return nullptr;
  }
}

void Deallocate(void* ptr) noexcept {
  CountDeallocation(ptr);
  std::free(ptr);
}

std::size_t ToSize(std::align_val_t alignment) { return static_cast<std::size_t>(alignment); }

}  // namespace

// NOLINTBEGIN(misc-new-delete-overloads): the full set is replaced on purpose.
void* operator new(std::size_t size) { return AllocateOrThrow(size, 0); }
void* operator new[](std::size_t size) { return AllocateOrThrow(size, 0); }
void* operator new(std::size_t size, std::align_val_t alignment) {
  return AllocateOrThrow(size, ToSize(alignment));
}
void* operator new[](std::size_t size, std::align_val_t alignment) {
  return AllocateOrThrow(size, ToSize(alignment));
}
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  return AllocateNoThrow(size, 0);
}
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
  return AllocateNoThrow(size, 0);
}
void* operator new(std::size_t size, std::align_val_t alignment, const std::nothrow_t&) noexcept {
  return AllocateNoThrow(size, ToSize(alignment));
}
void* operator new[](std::size_t size, std::align_val_t alignment, const std::nothrow_t&) noexcept {
  return AllocateNoThrow(size, ToSize(alignment));
}

void operator delete(void* ptr) noexcept { Deallocate(ptr); }
void operator delete[](void* ptr) noexcept { Deallocate(ptr); }
void operator delete(void* ptr, std::size_t) noexcept { Deallocate(ptr); }
void operator delete[](void* ptr, std::size_t) noexcept { Deallocate(ptr); }
void operator delete(void* ptr, std::align_val_t) noexcept { Deallocate(ptr); }
void operator delete[](void* ptr, std::align_val_t) noexcept { Deallocate(ptr); }
void operator delete(void* ptr, std::size_t, std::align_val_t) noexcept { Deallocate(ptr); }
void operator delete[](void* ptr, std::size_t, std::align_val_t) noexcept { Deallocate(ptr); }
void operator delete(void* ptr, const std::nothrow_t&) noexcept { Deallocate(ptr); }
void operator delete[](void* ptr, const std::nothrow_t&) noexcept { Deallocate(ptr); }
void operator delete(void* ptr, std::align_val_t, const std::nothrow_t&) noexcept {
  Deallocate(ptr);
}
void operator delete[](void* ptr, std::align_val_t, const std::nothrow_t&) noexcept {
  Deallocate(ptr);
}
// NOLINTEND(misc-new-delete-overloads)

namespace rover::testing {

uint64_t AllocationCounter::ThreadAllocations() { return t_allocations; }
uint64_t AllocationCounter::ThreadDeallocations() { return t_deallocations; }
uint64_t AllocationCounter::ThreadAllocatedBytes() { return t_allocated_bytes; }
uint64_t AllocationCounter::ProcessAllocations() {
  return g_process_allocations.load(std::memory_order_relaxed);
}

ScopedAllocationCheck::ScopedAllocationCheck()
    : allocations_at_start_(t_allocations),
      deallocations_at_start_(t_deallocations),
      bytes_at_start_(t_allocated_bytes) {}

uint64_t ScopedAllocationCheck::allocations() const {
  return t_allocations - allocations_at_start_;
}
uint64_t ScopedAllocationCheck::deallocations() const {
  return t_deallocations - deallocations_at_start_;
}
uint64_t ScopedAllocationCheck::allocated_bytes() const {
  return t_allocated_bytes - bytes_at_start_;
}

}  // namespace rover::testing
