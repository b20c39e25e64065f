#ifndef ROVER_MAPPING_LOOP_MATCH_DATA_STORE_H_
#define ROVER_MAPPING_LOOP_MATCH_DATA_STORE_H_

// The matching data of every submap a mission has made, in bounded memory.
// Any old submap can pair with a new one (the rover may come back to any
// place), so none can be dropped; but a submap's data is about a megabyte,
// and a mission makes hundreds. The store keeps the most recently used
// ones in memory and the others in a spill file, from which Get() reads
// them back: a revisit reads a handful of submaps, each in milliseconds
// against the second its data took to compute.
//
// The spill file is a temporary file opened unlinked (O_TMPFILE) in a
// directory the owner picks: on the board, the log partition rather than a
// RAM-backed /tmp. Nothing is left behind when the process ends, cleanly
// or not. Data read back match bit for bit (SubmapMatchData::Deserialize).
//
// Not thread-safe: the owner serialises calls. Data handed out stay valid
// while the caller holds them, whatever the store evicts.

#include <cstddef>
#include <cstdint>
#include <list>
#include <map>
#include <memory>
#include <string>

#include "mapping/loop/submap_match_data.h"

namespace rover::mapping {

struct MatchDataStoreOptions {
  /// Submaps whose data stay in memory, the most recently used; the rest
  /// go to the spill file. 0 keeps every submap's data in memory (no file).
  int resident_submaps = 8;
  /// Directory of the spill file; empty: $TMPDIR, else /tmp.
  std::string spill_directory;

  /// Throws std::invalid_argument "MatchDataStoreOptions.<key>: ...".
  void Validate() const;
};

struct MatchDataStoreStats {
  std::size_t submaps = 0;   ///< held, in memory or spilled
  std::size_t resident = 0;  ///< in memory
  uint64_t spilled_bytes = 0;
  uint64_t spill_writes = 0;
  uint64_t spill_reads = 0;
};

class MatchDataStore {
 public:
  /// `data_options` are those every stored submap's data were built with
  /// (reading back needs them). Throws std::invalid_argument for invalid
  /// options; the spill file is opened on first need.
  MatchDataStore(const MatchDataStoreOptions& options, const SubmapMatchDataOptions& data_options);
  ~MatchDataStore();
  MatchDataStore(const MatchDataStore&) = delete;
  MatchDataStore& operator=(const MatchDataStore&) = delete;

  /// Stores `data` (non-null) under `key`, replacing what was there, as the
  /// most recently used. May spill the least recently used; if that fails
  /// (the directory cannot take a file, the disk is full), the data stay in
  /// memory and std::runtime_error names the spill directory and the
  /// error. Nothing is lost either way.
  void Put(int64_t key, std::shared_ptr<const SubmapMatchData> data);

  /// The data under `key`, null if none: from memory, or read back from
  /// the spill file (and then the most recently used). Throws
  /// std::runtime_error naming the key if the spill file cannot be read
  /// back; the key is then forgotten.
  std::shared_ptr<const SubmapMatchData> Get(int64_t key);

  bool Contains(int64_t key) const { return entries_.count(key) > 0; }
  /// Forgets `key` (its spilled bytes stay in the file until the end).
  void Erase(int64_t key);

  MatchDataStoreStats Stats() const;
  /// The spill file's directory as opened; empty until something spilled.
  const std::string& spill_directory() const { return spill_directory_; }

 private:
  struct Entry {
    std::shared_ptr<const SubmapMatchData> data;  ///< null while spilled
    std::list<int64_t>::iterator recent;          ///< valid while resident
    uint64_t offset = 0;                          ///< in the spill file
    uint64_t bytes = 0;                           ///< 0: never written
  };

  void MakeMostRecent(int64_t key, Entry* entry);
  // Spills the least recently used until at most `resident` are in memory.
  void EvictDownTo(std::size_t resident);
  void OpenSpill();
  void Write(Entry* entry);
  std::shared_ptr<const SubmapMatchData> Read(int64_t key, const Entry& entry) const;

  const MatchDataStoreOptions options_;
  const SubmapMatchDataOptions data_options_;
  std::map<int64_t, Entry> entries_;
  std::list<int64_t> recent_;  ///< resident keys, most recent first
  int fd_ = -1;
  std::string spill_directory_;
  uint64_t end_ = 0;  ///< bytes written to the spill file
  MatchDataStoreStats stats_;
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_LOOP_MATCH_DATA_STORE_H_
