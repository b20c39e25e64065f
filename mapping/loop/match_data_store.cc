#include "mapping/loop/match_data_store.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string_view>
#include <utility>
#include <vector>

namespace rover::mapping {
namespace {

std::string ErrnoText(int error) { return std::strerror(error); }

std::string DefaultDirectory() {
  const char* tmpdir = std::getenv("TMPDIR");
  return tmpdir != nullptr && *tmpdir != '\0' ? tmpdir : "/tmp";
}

// An unlinked file in `directory`: O_TMPFILE where the filesystem has it,
// else a named file unlinked at once. -1 and errno on failure.
int OpenUnlinked(const std::string& directory) {
  const int fd = ::open(directory.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
  if (fd >= 0 || (errno != EOPNOTSUPP && errno != EISDIR && errno != EINVAL)) return fd;
  std::string path = directory + "/rover-match-data-XXXXXX";
  std::vector<char> name(path.begin(), path.end());
  name.push_back('\0');
  const int named = ::mkostemp(name.data(), O_CLOEXEC);
  if (named >= 0) ::unlink(name.data());
  return named;
}

}  // namespace

void MatchDataStoreOptions::Validate() const {
  if (resident_submaps < 0) {
    throw std::invalid_argument(
        "MatchDataStoreOptions.resident_submaps: expected >= 0 (0 keeps all in memory), found " +
        std::to_string(resident_submaps));
  }
}

MatchDataStore::MatchDataStore(const MatchDataStoreOptions& options,
                               const SubmapMatchDataOptions& data_options)
    : options_(options), data_options_(data_options) {
  options_.Validate();
  data_options_.Validate();
}

MatchDataStore::~MatchDataStore() {
  if (fd_ >= 0) ::close(fd_);
}

void MatchDataStore::Put(int64_t key, std::shared_ptr<const SubmapMatchData> data) {
  if (!data)
    throw std::invalid_argument("MatchDataStore::Put: null data for key " + std::to_string(key));
  Erase(key);
  Entry& entry = entries_[key];
  entry.data = std::move(data);
  recent_.push_front(key);
  entry.recent = recent_.begin();
  if (options_.resident_submaps > 0) {
    EvictDownTo(static_cast<std::size_t>(options_.resident_submaps));
  }
}

std::shared_ptr<const SubmapMatchData> MatchDataStore::Get(int64_t key) {
  const auto it = entries_.find(key);
  if (it == entries_.end()) return nullptr;
  Entry& entry = it->second;
  if (entry.data) {
    MakeMostRecent(key, &entry);
    return entry.data;
  }
  std::shared_ptr<const SubmapMatchData> data;
  try {
    data = Read(key, entry);
  } catch (const std::exception&) {
    entries_.erase(it);
    throw;
  }
  ++stats_.spill_reads;
  // Room first: if spilling another fails, this one is still safely spilled.
  if (options_.resident_submaps > 0) {
    EvictDownTo(static_cast<std::size_t>(options_.resident_submaps) - 1);
  }
  entry.data = data;
  recent_.push_front(key);
  entry.recent = recent_.begin();
  return data;
}

void MatchDataStore::Erase(int64_t key) {
  const auto it = entries_.find(key);
  if (it == entries_.end()) return;
  if (it->second.data) recent_.erase(it->second.recent);
  entries_.erase(it);
}

MatchDataStoreStats MatchDataStore::Stats() const {
  MatchDataStoreStats stats = stats_;
  stats.submaps = entries_.size();
  stats.resident = recent_.size();
  stats.spilled_bytes = end_;
  return stats;
}

void MatchDataStore::MakeMostRecent(int64_t key, Entry* entry) {
  recent_.erase(entry->recent);
  recent_.push_front(key);
  entry->recent = recent_.begin();
}

void MatchDataStore::EvictDownTo(std::size_t resident) {
  while (recent_.size() > resident) {
    Entry& victim = entries_.at(recent_.back());
    // Written once: the data never change, so a second eviction only drops.
    if (victim.bytes == 0) Write(&victim);
    victim.data.reset();
    recent_.pop_back();
  }
}

void MatchDataStore::OpenSpill() {
  const std::string directory =
      options_.spill_directory.empty() ? DefaultDirectory() : options_.spill_directory;
  fd_ = OpenUnlinked(directory);
  if (fd_ < 0) {
    throw std::runtime_error("MatchDataStore: cannot open a spill file in " + directory + ": " +
                             ErrnoText(errno) + "; the match data stay in memory");
  }
  spill_directory_ = directory;
}

void MatchDataStore::Write(Entry* entry) {
  if (fd_ < 0) OpenSpill();
  const std::string bytes = entry->data->Serialize();
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n =
        ::pwrite(fd_, bytes.data() + done, bytes.size() - done, static_cast<off_t>(end_ + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      throw std::runtime_error("MatchDataStore: writing " + std::to_string(bytes.size()) +
                               " bytes to the spill file in " + spill_directory_ + ": " +
                               ErrnoText(n < 0 ? errno : ENOSPC) +
                               "; the match data stay in memory");
    }
    done += static_cast<std::size_t>(n);
  }
  entry->offset = end_;
  entry->bytes = bytes.size();
  end_ += bytes.size();
  ++stats_.spill_writes;
}

std::shared_ptr<const SubmapMatchData> MatchDataStore::Read(int64_t key, const Entry& entry) const {
  std::string bytes(entry.bytes, '\0');
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::pread(fd_, bytes.data() + done, bytes.size() - done,
                              static_cast<off_t>(entry.offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      throw std::runtime_error("MatchDataStore: reading submap " + std::to_string(key) +
                               " back from the spill file in " + spill_directory_ + ": " +
                               (n < 0 ? ErrnoText(errno) : std::string("unexpected end of file")));
    }
    done += static_cast<std::size_t>(n);
  }
  try {
    return SubmapMatchData::Deserialize(bytes, data_options_);
  } catch (const std::exception& e) {
    throw std::runtime_error("MatchDataStore: submap " + std::to_string(key) +
                             " read back from the spill file in " + spill_directory_ + ": " +
                             e.what());
  }
}

}  // namespace rover::mapping
