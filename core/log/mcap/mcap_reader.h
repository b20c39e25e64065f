#ifndef ROVER_CORE_LOG_MCAP_MCAP_READER_H_
#define ROVER_CORE_LOG_MCAP_MCAP_READER_H_

// MCAP reader for host tools: reads complete, truncated and damaged files.
//
// Open() trusts the summary section only when the footer, the summary CRC and
// every chunk index check out; otherwise it scans the data section record by
// record, which works for a file cut at any byte (power loss while logging)
// and reports what it could not read as Damage entries with file offsets.
// Every length in the file is bounds-checked, decompressed sizes are capped
// (1 GiB, and at the best ratio the codec can reach), unknown opcodes are
// skipped as the spec requires; hostile input neither crashes the reader nor
// makes it allocate without bound.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/log/mcap/mcap_types.h"
#include "core/log/mcap/mcap_writer.h"

namespace rover::log {

enum class ChunkStatus {
  kUnverified,  ///< Framing is intact; not decompressed yet.
  kOk,          ///< Decompressed, CRC matched, records parsed.
  kDamaged,     ///< Unreadable; see McapReader::damage() for why.
};

/// One Chunk record (op 0x06) of the file.
struct ChunkInfo {
  uint64_t offset = 0;  ///< File offset of the record's opcode byte.
  uint64_t length = 0;  ///< Record length including the 9-byte prefix.
  uint64_t message_start_time = 0;
  uint64_t message_end_time = 0;
  std::string compression;         ///< "", "zstd" or "lz4" (or whatever the file says).
  uint64_t compressed_size = 0;    ///< Size of the stored records field.
  uint64_t uncompressed_size = 0;  ///< Declared size of the records once decompressed.
  uint32_t uncompressed_crc = 0;   ///< 0: the writer did not store a CRC.
  /// From the chunk's Message Index records until the chunk is decoded, then
  /// the number of Message records actually in it.
  uint64_t message_count = 0;
  /// Channel id -> file offset of the chunk's Message Index record.
  std::map<uint16_t, uint64_t> message_index_offsets;
  uint64_t message_index_length = 0;  ///< Bytes of Message Index records after the chunk.
  ChunkStatus status = ChunkStatus::kUnverified;
};

/// A message handed to ForEachMessage(). `data` is valid during the callback only.
struct MessageView {
  uint16_t channel_id = 0;
  uint32_t sequence = 0;
  uint64_t log_time = 0;
  uint64_t publish_time = 0;
  std::span<const std::byte> data;
};

struct ReadOptions {
  enum class Order {
    kFile,     ///< As stored: chunk by chunk, record by record.
    kLogTime,  ///< By log_time (ties in file order), merging overlapping chunks.
  };
  Order order = Order::kFile;
  uint64_t start_time = 0;            ///< Only messages with log_time >= start_time ...
  uint64_t end_time = UINT64_MAX;     ///< ... and log_time <= end_time.
  std::vector<uint16_t> channel_ids;  ///< Only these channels; empty means all.
};

struct OpenOptions {
  /// Use the summary section when it is intact. False forces the linear scan
  /// of the data section (what Recover() uses, as it also finds messages
  /// outside chunks and chunks missing from the index).
  bool use_summary = true;
};

/// Result of McapReader::Verify() / Verify().
struct VerifyReport {
  bool ok = false;             ///< No damage, no truncation.
  std::vector<Damage> damage;  ///< Everything found, in file order where possible.
  bool summary_ok = false;     ///< The summary was intact and agreed with the data section.
  bool truncated = false;      ///< The file does not end with Footer + magic.
  uint64_t message_count = 0;  ///< Messages in intact chunks and outside chunks.
  uint64_t chunk_count = 0;    ///< Chunks found by the data section scan.
  uint64_t damaged_chunk_count = 0;
  uint64_t schema_count = 0;
  uint64_t channel_count = 0;
  uint64_t metadata_count = 0;
  uint64_t attachment_count = 0;
};

class McapReader {
 public:
  /// Maps `path` read-only and indexes it (no chunk is decompressed yet).
  /// Throws McapError if the file cannot be read, does not start with the
  /// MCAP magic, or has no complete Header record; any later damage, including
  /// truncation, is reported through damage() instead.
  static McapReader Open(const std::string& path, const OpenOptions& options = {});
  /// As Open(path) for bytes in memory; the bytes are copied.
  static McapReader Open(std::span<const std::byte> bytes, const OpenOptions& options = {});

  McapReader(McapReader&&) noexcept;
  McapReader& operator=(McapReader&&) noexcept;
  ~McapReader();

  const Header& header() const;
  /// Schemas and channels by id: from the summary, or from the data section
  /// scan (including those found inside chunks decoded so far).
  const std::map<uint16_t, Schema>& schemas() const;
  const std::map<uint16_t, Channel>& channels() const;
  const std::vector<Metadata>& metadata() const;
  const std::vector<AttachmentInfo>& attachments() const;
  /// The Statistics record of the summary, if the summary is used.
  const std::optional<Statistics>& statistics() const;
  /// Chunks in file order.
  const std::vector<ChunkInfo>& chunks() const;
  /// True when the summary was intact and is what this reader indexes from.
  bool summary_ok() const;
  /// True when the file does not end with a Footer record and the magic.
  bool truncated() const;
  /// Damage found so far: by Open(), then by ForEachMessage() and
  /// ReadAttachment() as they decode more of the file. A truncated file
  /// always has an entry saying where it ends. (Verify() returns its findings
  /// in its report instead.)
  const std::vector<Damage>& damage() const;
  uint64_t file_size() const;

  /// Calls `fn` for every readable message until it returns false. Each chunk
  /// is decompressed and its uncompressed CRC checked first; a chunk that
  /// fails is added to damage() (with its file offset) and none of its
  /// messages are delivered. Messages outside chunks are delivered only when
  /// the data section was scanned (the MCAP index covers chunks only).
  /// Not reentrant: `fn` must not call ForEachMessage() on the same reader.
  void ForEachMessage(const std::function<bool(const MessageView&)>& fn,
                      const ReadOptions& options = {});

  /// The data of `attachment`, or nullopt (and a damage() entry) if its
  /// record is unreadable or fails its CRC.
  std::optional<std::vector<std::byte>> ReadAttachment(const AttachmentInfo& attachment);

  /// Checks everything: data section CRC, summary CRC, every chunk's CRC and
  /// contents, message indexes against chunk contents, chunk indexes against
  /// the chunks, statistics against the counted messages, channels against
  /// schemas, attachment CRCs, truncation. Scans the data section even when
  /// the summary is intact. Never throws for damage.
  VerifyReport Verify();

 private:
  struct Impl;
  explicit McapReader(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

/// Opens and verifies `path`. An unreadable file or a non-MCAP file gives a
/// report with ok == false and the reason at offset 0 (never throws McapError).
VerifyReport Verify(const std::string& path);
/// As Verify(path) for bytes in memory.
VerifyReport Verify(std::span<const std::byte> bytes);

struct RecoverResult {
  uint64_t messages_written = 0;  ///< Messages copied into the new file.
  uint64_t chunks_recovered = 0;  ///< Intact chunks of the input.
  uint64_t chunks_dropped = 0;    ///< Damaged chunks of the input.
  /// Messages lost with dropped chunks, as counted by their message indexes
  /// (chunks without an index count as 0), plus messages on unknown channels.
  uint64_t messages_dropped = 0;
  bool input_truncated = false;
  std::vector<Damage> dropped;  ///< The damage of the input, i.e. what was not copied.
};

/// Rewrites everything readable in `in` (schemas, channels, metadata,
/// attachments that pass their CRC, and all messages of intact chunks and
/// outside chunks, in file order, with their ids unchanged) into a new, valid
/// file `out` written with `options` (the profile is taken from the input).
/// Throws McapError if `in` is not an MCAP file or `out` cannot be written.
RecoverResult Recover(const std::string& in, const std::string& out,
                      const McapWriterOptions& options = {});

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_MCAP_MCAP_READER_H_
