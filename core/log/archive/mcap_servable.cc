#include "core/log/archive/mcap_servable.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <stdexcept>
#include <system_error>

#include "core/log/mcap/mcap_format.h"
#include "core/log/mcap/mcap_reader.h"

namespace rover::log {
namespace {

using internal::LoadLe;
using internal::Opcode;

constexpr size_t kTailSampleBytes = 64;
/// Chunk body start: message_start_time, message_end_time, uncompressed_size.
constexpr uint64_t kChunkTimesBytes = 24;
/// Message body start: channel_id (2), sequence (4), log_time (8).
constexpr uint64_t kMessageTimeBytes = 14;

std::string ErrnoText(int err) { return std::error_code(err, std::generic_category()).message(); }

// Reads exactly out.size() bytes at `offset`; false if the file ends first.
bool ReadAt(int fd, uint64_t offset, std::span<std::byte> out, const std::string& name) {
  size_t done = 0;
  while (done < out.size()) {
    const ssize_t got =
        ::pread(fd, out.data() + done, out.size() - done, static_cast<off_t>(offset + done));
    if (got < 0) {
      if (errno == EINTR) continue;
      throw std::runtime_error(name + ": read of " + std::to_string(out.size()) +
                               " bytes at offset " + std::to_string(offset) +
                               " failed: " + ErrnoText(errno));
    }
    if (got == 0) return false;
    done += static_cast<size_t>(got);
  }
  return true;
}

void Extend(std::optional<uint64_t>& start, std::optional<uint64_t>& end, uint64_t t) {
  if (!start || t < *start) start = t;
  if (!end || t > *end) end = t;
}

// True when the file ends with a framed Footer record and the closing magic:
// worth asking McapReader whether the summary is intact.
bool TailLooksComplete(int fd, uint64_t size, const std::string& name) {
  const uint64_t tail = internal::kFooterRecordSize + internal::kMagic.size();
  if (size < internal::kMagic.size() + tail) return false;
  std::array<std::byte, internal::kFooterRecordSize + internal::kMagic.size()> bytes{};
  if (!ReadAt(fd, size - tail, bytes, name)) return false;
  if (!std::equal(internal::kMagic.begin(), internal::kMagic.end(),
                  bytes.begin() + internal::kFooterRecordSize)) {
    return false;
  }
  return bytes[0] == static_cast<std::byte>(Opcode::kFooter) &&
         LoadLe<uint64_t>(bytes.data() + 1) == internal::kFooterBodySize;
}

struct SummaryFacts {
  std::optional<uint64_t> start_time_ns;
  std::optional<uint64_t> end_time_ns;
};

// McapReader's verdict on a file that looks complete: the time range from its
// summary, or nullopt if the summary is not intact.
std::optional<SummaryFacts> ReadSummary(int fd) {
  try {
    // The fd's own /proc link: the very file examined, even if renamed since.
    McapReader reader = McapReader::Open("/proc/self/fd/" + std::to_string(fd));
    if (!reader.summary_ok() || reader.truncated()) return std::nullopt;
    SummaryFacts facts;
    if (reader.statistics() && reader.statistics()->message_count > 0) {
      facts.start_time_ns = reader.statistics()->message_start_time;
      facts.end_time_ns = reader.statistics()->message_end_time;
    } else if (!reader.statistics()) {
      for (const ChunkInfo& chunk : reader.chunks()) {
        if (chunk.uncompressed_size == 0) continue;
        Extend(facts.start_time_ns, facts.end_time_ns, chunk.message_start_time);
        Extend(facts.start_time_ns, facts.end_time_ns, chunk.message_end_time);
      }
    }
    return facts;
  } catch (const McapError&) {
    return std::nullopt;
  }
}

}  // namespace

void McapServableTracker::Reset() {
  has_identity_ = false;
  mtime_ns_ = -1;
  info_valid_ = false;
  info_ = {};
  walk_ = {};
  sha_ = Sha256();
  tail_sample_.clear();
}

const McapServableInfo& McapServableTracker::Update(int fd, const std::string& name) {
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    throw std::runtime_error(name + ": fstat failed: " + ErrnoText(errno));
  }
  if (!S_ISREG(st.st_mode)) {
    throw std::runtime_error(name + ": expected a regular file, found another kind of file");
  }
  if (has_identity_ && (st.st_dev != dev_ || st.st_ino != ino_)) Reset();
  has_identity_ = true;
  dev_ = st.st_dev;
  ino_ = st.st_ino;
  const auto size = static_cast<uint64_t>(st.st_size);
  const int64_t mtime_ns = static_cast<int64_t>(st.st_mtim.tv_sec) * 1'000'000'000 +
                           static_cast<int64_t>(st.st_mtim.tv_nsec);
  if (info_valid_ && size == info_.file_size_bytes && mtime_ns == mtime_ns_) return info_;

  // Only growth is incremental; anything else starts over.
  if (size < sha_.size_bytes() || size < walk_.next_offset || !TailSampleMatches(fd, name)) {
    Reset();
    has_identity_ = true;
    dev_ = st.st_dev;
    ino_ = st.st_ino;
  }

  McapServableInfo info;
  info.file_size_bytes = size;
  std::optional<SummaryFacts> summary;
  if (TailLooksComplete(fd, size, name)) summary = ReadSummary(fd);
  if (summary) {
    info.complete = true;
    info.servable_length_bytes = size;
    info.start_time_ns = summary->start_time_ns;
    info.end_time_ns = summary->end_time_ns;
  } else {
    WalkRecords(fd, size, name);
    info.servable_length_bytes = walk_.header_seen ? walk_.next_offset : 0;
    info.start_time_ns = walk_.start_time_ns;
    info.end_time_ns = walk_.end_time_ns;
  }
  HashUpTo(fd, info.servable_length_bytes, name);
  info.sha256 = sha_.HexDigest();

  info_ = std::move(info);
  mtime_ns_ = mtime_ns;
  info_valid_ = true;
  return info_;
}

void McapServableTracker::WalkRecords(int fd, uint64_t size, const std::string& name) {
  if (walk_.not_mcap) return;
  if (walk_.next_offset == 0) {
    std::array<std::byte, internal::kMagic.size()> magic{};
    if (size < magic.size() || !ReadAt(fd, 0, magic, name)) return;
    if (magic != internal::kMagic) {
      walk_.not_mcap = true;
      return;
    }
    walk_.next_offset = magic.size();
  }
  std::array<std::byte, internal::kRecordPrefixSize> prefix{};
  std::array<std::byte, kChunkTimesBytes> body{};
  for (;;) {
    const uint64_t pos = walk_.next_offset;
    if (size - pos < prefix.size()) return;
    if (!ReadAt(fd, pos, prefix, name)) return;
    const auto opcode = static_cast<uint8_t>(prefix[0]);
    const auto length = LoadLe<uint64_t>(prefix.data() + 1);
    if (length > size - pos - prefix.size()) return;  // Being written, or cut.
    if (!walk_.header_seen) {
      if (opcode != static_cast<uint8_t>(Opcode::kHeader)) {
        walk_.not_mcap = true;
        return;
      }
      walk_.header_seen = true;
    }
    const uint64_t body_at = pos + prefix.size();
    if (opcode == static_cast<uint8_t>(Opcode::kChunk) && length >= kChunkTimesBytes) {
      if (!ReadAt(fd, body_at, std::span(body).first(kChunkTimesBytes), name)) return;
      if (LoadLe<uint64_t>(body.data() + 16) > 0) {  // uncompressed_size: the chunk has records
        Extend(walk_.start_time_ns, walk_.end_time_ns, LoadLe<uint64_t>(body.data()));
        Extend(walk_.start_time_ns, walk_.end_time_ns, LoadLe<uint64_t>(body.data() + 8));
      }
    } else if (opcode == static_cast<uint8_t>(Opcode::kMessage) && length >= kMessageTimeBytes) {
      if (!ReadAt(fd, body_at, std::span(body).first(kMessageTimeBytes), name)) return;
      Extend(walk_.start_time_ns, walk_.end_time_ns, LoadLe<uint64_t>(body.data() + 6));
    }
    walk_.next_offset = body_at + length;
  }
}

bool McapServableTracker::TailSampleMatches(int fd, const std::string& name) const {
  if (tail_sample_.empty()) return true;
  std::vector<std::byte> now(tail_sample_.size());
  return ReadAt(fd, sha_.size_bytes() - now.size(), now, name) && now == tail_sample_;
}

void McapServableTracker::HashUpTo(int fd, uint64_t length_bytes, const std::string& name) {
  if (length_bytes < sha_.size_bytes()) {
    // Servable bytes never shrink for a file that only grows; start over.
    sha_ = Sha256();
  }
  Sha256UpdateFromFile(fd, sha_.size_bytes(), length_bytes - sha_.size_bytes(), name, &sha_);
  tail_sample_.resize(static_cast<size_t>(std::min<uint64_t>(kTailSampleBytes, length_bytes)));
  if (!tail_sample_.empty() &&
      !ReadAt(fd, length_bytes - tail_sample_.size(), tail_sample_, name)) {
    throw std::runtime_error(name + ": expected " + std::to_string(length_bytes) +
                             " bytes, found the file shorter while hashing it");
  }
}

}  // namespace rover::log
