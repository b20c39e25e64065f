#ifndef ROVER_TESTS_SUPPORT_ALLOCATION_COUNTER_H_
#define ROVER_TESTS_SUPPORT_ALLOCATION_COUNTER_H_

// Counts heap allocations so tests can prove that a real-time path never
// allocates.
//
// allocation_counter.cc replaces every global operator new / operator delete
// (plain, array, aligned, nothrow and sized forms) with versions that forward
// to malloc/free and bump per-thread counters. Per-thread counts matter
// because gtest, iceoryx and other background threads allocate whenever they
// like; a check must only see the thread that runs the code under test.
//
// Only allocations made through operator new are seen: a direct malloc() call
// (e.g. inside a C library) is invisible. Real-time code is C++ and allocates
// through new/std::allocator, so that is the path that matters.
//
// The replacement must be linked exactly once into the test executable, which
// is why rover_test_support is an OBJECT library (see its CMakeLists.txt).
//
// Note: this declares namespace rover::testing. Inside `namespace rover`,
// refer to GoogleTest as ::testing (the gtest macros already do).

#include <cstdint>

namespace rover::testing {

/// Read-only view of the allocation counters maintained by the replaced
/// global operator new/delete. All functions are thread-safe and never
/// allocate.
class AllocationCounter {
 public:
  AllocationCounter() = delete;

  /// Number of successful operator new calls (all forms) made by the calling
  /// thread since it started.
  static uint64_t ThreadAllocations();
  /// Number of operator delete calls with a non-null pointer made by the
  /// calling thread since it started.
  static uint64_t ThreadDeallocations();
  /// Number of bytes requested from operator new by the calling thread.
  static uint64_t ThreadAllocatedBytes();
  /// Number of successful operator new calls made by all threads since
  /// process start (relaxed counter, for diagnostics only).
  static uint64_t ProcessAllocations();
};

/// Snapshot of the calling thread's counters taken at construction; reports
/// what the same thread allocated since then. Use one per check:
///
///   ScopedAllocationCheck check;
///   ring.TryPush(item);
///   EXPECT_EQ(check.allocations(), 0u);
///
/// Must be read on the thread that constructed it (the counters are
/// thread-local, so reading elsewhere would compare unrelated threads).
class ScopedAllocationCheck {
 public:
  ScopedAllocationCheck();
  ScopedAllocationCheck(const ScopedAllocationCheck&) = delete;
  ScopedAllocationCheck& operator=(const ScopedAllocationCheck&) = delete;

  /// operator new calls made by this thread since construction.
  uint64_t allocations() const;
  /// operator delete calls (non-null pointer) made by this thread since
  /// construction.
  uint64_t deallocations() const;
  /// Bytes requested from operator new by this thread since construction.
  uint64_t allocated_bytes() const;

 private:
  uint64_t allocations_at_start_;
  uint64_t deallocations_at_start_;
  uint64_t bytes_at_start_;
};

}  // namespace rover::testing

#endif  // ROVER_TESTS_SUPPORT_ALLOCATION_COUNTER_H_
