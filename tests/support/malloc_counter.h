#ifndef ROVER_TESTS_SUPPORT_MALLOC_COUNTER_H_
#define ROVER_TESTS_SUPPORT_MALLOC_COUNTER_H_

// Counts C-level heap allocations (malloc, calloc, realloc, aligned_alloc,
// posix_memalign, memalign) per thread, complementing AllocationCounter,
// which only sees operator new. Eigen allocates its dynamic matrices with
// malloc directly, so a real-time numeric path must be checked here too.
//
// malloc_counter.cc interposes those functions in the test executable and
// forwards to glibc's __libc_* implementations. Link the OBJECT library
// rover_test_malloc_counter into a test executable only, and never into a
// sanitizer build (the sanitizers interpose malloc themselves).

#include <cstdint>

namespace rover::testing {

class MallocCounter {
 public:
  MallocCounter() = delete;
  /// malloc-family calls made by the calling thread since it started.
  static uint64_t ThreadMallocs();
};

/// Snapshot of the calling thread's malloc count; reports the calls made by
/// the same thread since construction.
class ScopedMallocCheck {
 public:
  ScopedMallocCheck() : start_(MallocCounter::ThreadMallocs()) {}
  uint64_t mallocs() const { return MallocCounter::ThreadMallocs() - start_; }

 private:
  uint64_t start_;
};

}  // namespace rover::testing

#endif  // ROVER_TESTS_SUPPORT_MALLOC_COUNTER_H_
