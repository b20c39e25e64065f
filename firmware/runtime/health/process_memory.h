#ifndef ROVER_FIRMWARE_RUNTIME_HEALTH_PROCESS_MEMORY_H_
#define ROVER_FIRMWARE_RUNTIME_HEALTH_PROCESS_MEMORY_H_

// What this process's memory is made of, for a long mission's logs: the
// kernel's resident set split by kind (/proc/self/status), and glibc's
// account of the heap (mallinfo2, over every arena). The split is what tells
// a leak from what is not one: anonymous RSS that grows while the heap's
// bytes in use stay flat is fragmentation (free bytes the allocator still
// holds), and shared-memory RSS grows as a process first touches more of
// the IPC pool, without any allocation at all.
//
// Reading costs a file read and a walk over the heap's arenas (well under a
// millisecond): call it from a housekeeping path, never the real-time loop.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/log/msgs/diagnostic_msgs.h"

namespace rover::runtime {

struct ProcessMemory {
  // Resident set from /proc/self/status [kB].
  uint64_t rss_kb = 0;
  uint64_t rss_anon_kb = 0;   ///< heap, stacks, private mappings
  uint64_t rss_file_kb = 0;   ///< code and mapped files
  uint64_t rss_shmem_kb = 0;  ///< shared memory (the IPC pool)
  // glibc's heap (mallinfo2) [bytes].
  uint64_t heap_in_use_bytes = 0;     ///< allocated and not freed, in arenas and mmapped
  uint64_t heap_free_held_bytes = 0;  ///< freed but still held in the arenas
  uint64_t heap_mmapped_bytes = 0;    ///< large blocks mmapped on their own (in use)
  uint64_t heap_arena_bytes = 0;      ///< taken from the system by the arenas

  /// Key/value pairs for a diagnostics status, names with their units
  /// ("rss_anon_kb", "heap_in_use_kb", ...).
  std::vector<log::diagnostic_msgs::KeyValue> ToKeyValues() const;
};

/// This process's memory now. Returns nullopt and sets `error` (naming the
/// file) if /proc/self/status cannot be read or lacks the RSS lines.
std::optional<ProcessMemory> ReadProcessMemory(std::string* error);

/// Parses the text of a /proc/<pid>/status file (RSS fields only; the heap
/// fields stay 0). Returns nullopt and sets `error` naming the missing field.
std::optional<ProcessMemory> ParseProcStatus(const std::string& text, std::string* error);

}  // namespace rover::runtime

#endif  // ROVER_FIRMWARE_RUNTIME_HEALTH_PROCESS_MEMORY_H_
