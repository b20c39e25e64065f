#include "firmware/runtime/health/process_memory.h"

#include <malloc.h>

#include <fstream>
#include <sstream>

namespace rover::runtime {
namespace {

// The value [kB] of the "Name:   123 kB" line of a status file.
std::optional<uint64_t> StatusField(const std::string& text, const std::string& name) {
  std::istringstream in(text);
  std::string line;
  const std::string prefix = name + ":";
  while (std::getline(in, line)) {
    if (line.compare(0, prefix.size(), prefix) != 0) continue;
    std::istringstream fields(line.substr(prefix.size()));
    uint64_t kb = 0;
    if (fields >> kb) return kb;
    return std::nullopt;
  }
  return std::nullopt;
}

}  // namespace

std::optional<ProcessMemory> ParseProcStatus(const std::string& text, std::string* error) {
  ProcessMemory m;
  const std::pair<const char*, uint64_t*> fields[] = {{"VmRSS", &m.rss_kb},
                                                      {"RssAnon", &m.rss_anon_kb},
                                                      {"RssFile", &m.rss_file_kb},
                                                      {"RssShmem", &m.rss_shmem_kb}};
  for (const auto& [name, value] : fields) {
    const std::optional<uint64_t> kb = StatusField(text, name);
    if (!kb) {
      if (error) *error = std::string("process status: expected a '") + name + ":' line in kB";
      return std::nullopt;
    }
    *value = *kb;
  }
  return m;
}

std::optional<ProcessMemory> ReadProcessMemory(std::string* error) {
  std::ifstream file("/proc/self/status");
  std::stringstream text;
  text << file.rdbuf();
  if (!file) {
    if (error) *error = "/proc/self/status: cannot be read";
    return std::nullopt;
  }
  std::optional<ProcessMemory> m = ParseProcStatus(text.str(), error);
  if (!m) {
    if (error) *error = "/proc/self/status: " + *error;
    return std::nullopt;
  }
  const struct mallinfo2 heap = ::mallinfo2();
  m->heap_in_use_bytes = heap.uordblks + heap.hblkhd;
  m->heap_free_held_bytes = heap.fordblks;
  m->heap_mmapped_bytes = heap.hblkhd;
  m->heap_arena_bytes = heap.arena;
  return m;
}

std::vector<log::diagnostic_msgs::KeyValue> ProcessMemory::ToKeyValues() const {
  const auto kb = [](uint64_t bytes) { return std::to_string(bytes / 1024); };
  return {
      {"rss_kb", std::to_string(rss_kb)},           {"rss_anon_kb", std::to_string(rss_anon_kb)},
      {"rss_file_kb", std::to_string(rss_file_kb)}, {"rss_shmem_kb", std::to_string(rss_shmem_kb)},
      {"heap_in_use_kb", kb(heap_in_use_bytes)},    {"heap_free_held_kb", kb(heap_free_held_bytes)},
      {"heap_mmapped_kb", kb(heap_mmapped_bytes)},  {"heap_arena_kb", kb(heap_arena_bytes)}};
}

}  // namespace rover::runtime
