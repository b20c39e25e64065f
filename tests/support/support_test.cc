// Tests of the test helpers themselves: a broken allocation counter would
// make every "does not allocate" check pass vacuously.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <new>
#include <string>
#include <thread>
#include <vector>

#include "tests/support/allocation_counter.h"
#include "tests/support/temp_dir.h"

namespace rover::testing {
namespace {

// Stores a pointer where the optimiser cannot see it: a new/delete pair whose
// pointer does not escape may legally be elided, and then nothing is counted.
void* volatile g_sink = nullptr;

template <typename P>
P Escape(P ptr) {
  g_sink = ptr;
  return ptr;
}

TEST(AllocationCounterTest, CountsEveryFormOfNewAndDelete) {
  struct alignas(128) Aligned {
    char c;
  };
  ScopedAllocationCheck check;
  delete Escape(new int(1));
  delete[] Escape(new char[10]);
  delete Escape(new Aligned);
  delete[] Escape(new Aligned[2]);
  delete Escape(new (std::nothrow) int(2));
  ::operator delete (Escape(::operator new (16, std::align_val_t{64}, std::nothrow)),
                     std::align_val_t{64});
  const uint64_t allocations = check.allocations();
  const uint64_t deallocations = check.deallocations();
  const uint64_t bytes = check.allocated_bytes();
  EXPECT_EQ(allocations, 6u);
  EXPECT_EQ(deallocations, 6u);
  EXPECT_GE(bytes, sizeof(int) + 10 + 3 * sizeof(Aligned) + 16);
}

TEST(AllocationCounterTest, CountsOnlyTheCallingThread) {
  ScopedAllocationCheck check;
  std::thread other([] {
    std::vector<int> v(1000);
    EXPECT_EQ(v.size(), 1000u);
  });
  other.join();  // std::thread itself allocates its state here, in this thread.
  const uint64_t after_thread = check.allocations();
  std::thread([] { Escape(std::make_unique<std::string>(100, 'x').get()); }).join();
  // Each thread start costs this thread the same; the work inside is unseen.
  EXPECT_EQ(check.allocations(), 2 * after_thread);
}

TEST(AllocationCounterTest, SeesStandardContainers) {
  ScopedAllocationCheck check;
  std::vector<double> v;
  v.reserve(100);
  Escape(v.data());
  const uint64_t allocations = check.allocations();
  EXPECT_EQ(allocations, 1u);
  EXPECT_GE(check.allocated_bytes(), 100 * sizeof(double));
}

TEST(TempDirTest, CreatesAUniqueDirectoryAndRemovesIt) {
  std::filesystem::path kept;
  {
    TempDir a;
    TempDir b;
    ASSERT_TRUE(std::filesystem::is_directory(a.path()));
    EXPECT_NE(a.path(), b.path());
    EXPECT_NE(a.path().filename().string().find("TempDirTest_CreatesAUniqueDirectoryAndRemovesIt"),
              std::string::npos);
    std::filesystem::create_directories(a.File("sub/dir"));
    std::ofstream(a.File("sub/dir/file.txt")) << "data";
    kept = a.path();
  }
  EXPECT_FALSE(std::filesystem::exists(kept));
}

}  // namespace
}  // namespace rover::testing
