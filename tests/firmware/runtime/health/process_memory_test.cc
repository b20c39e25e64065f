#include "firmware/runtime/health/process_memory.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <string>

namespace rover::runtime {
namespace {

constexpr const char* kStatus =
    "Name:\tmapd\nVmPeak:\t  900000 kB\nVmRSS:\t   81072 kB\nRssAnon:\t   55000 kB\n"
    "RssFile:\t   20000 kB\nRssShmem:\t    6072 kB\nThreads:\t8\n";

TEST(ProcessMemoryTest, ParsesTheResidentSetByKind) {
  std::string error;
  const auto m = ParseProcStatus(kStatus, &error);
  ASSERT_TRUE(m.has_value()) << error;
  EXPECT_EQ(m->rss_kb, 81072u);
  EXPECT_EQ(m->rss_anon_kb, 55000u);
  EXPECT_EQ(m->rss_file_kb, 20000u);
  EXPECT_EQ(m->rss_shmem_kb, 6072u);
}

TEST(ProcessMemoryTest, AMissingFieldIsNamed) {
  std::string text = kStatus;
  text.erase(text.find("RssShmem"));
  std::string error;
  EXPECT_FALSE(ParseProcStatus(text, &error).has_value());
  EXPECT_NE(error.find("RssShmem"), std::string::npos) << error;
  error.clear();
  EXPECT_FALSE(ParseProcStatus("VmRSS:\tlots\n", &error).has_value());
  EXPECT_NE(error.find("VmRSS"), std::string::npos) << error;
}

TEST(ProcessMemoryTest, SeesAnAllocationInTheHeapAndTheResidentSet) {
  std::string error;
  const auto before = ReadProcessMemory(&error);
  ASSERT_TRUE(before.has_value()) << error;
  constexpr std::size_t kBytes = 64u << 20;
  char* block = static_cast<char*>(std::malloc(kBytes));
  ASSERT_NE(block, nullptr);
  std::memset(block, 1, kBytes);  // resident only once touched
  const auto during = ReadProcessMemory(&error);
  ASSERT_TRUE(during.has_value()) << error;
  EXPECT_GE(during->heap_in_use_bytes, before->heap_in_use_bytes + kBytes);
  EXPECT_GE(during->rss_anon_kb, before->rss_anon_kb + (kBytes >> 10) * 9 / 10);
  EXPECT_LE(during->rss_anon_kb, during->rss_kb);
  volatile char sink = block[kBytes / 2];
  (void)sink;
  std::free(block);
  const auto after = ReadProcessMemory(&error);
  ASSERT_TRUE(after.has_value()) << error;
  EXPECT_LT(after->heap_in_use_bytes, during->heap_in_use_bytes - kBytes / 2);

  const auto values = during->ToKeyValues();
  ASSERT_FALSE(values.empty());
  EXPECT_EQ(values[1].key, "rss_anon_kb");
  EXPECT_EQ(values[1].value, std::to_string(during->rss_anon_kb));
}

}  // namespace
}  // namespace rover::runtime
