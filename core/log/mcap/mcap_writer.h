#ifndef ROVER_CORE_LOG_MCAP_MCAP_WRITER_H_
#define ROVER_CORE_LOG_MCAP_MCAP_WRITER_H_

// Crash-safe MCAP writer for the flight log (https://mcap.dev/spec).
//
// File layout:
//   magic, Header,
//   Schema / Channel / Metadata / Attachment records as soon as they are added,
//   Chunk + its Message Index records (one write(2) per chunk), ...,
//   Data End (data section CRC), summary (Schemas, Channels, Statistics,
//   Chunk Indexes, Attachment Indexes, Metadata Indexes), Summary Offsets,
//   Footer (summary CRC), magic.
//
// Crash safety: everything a reader needs to decode a chunk (its schema and
// channel records) is on disk before the chunk, and a chunk is only written
// when complete, with its CRC. A file cut at any byte (power loss, full disk)
// therefore stays readable up to its last complete chunk, and McapReader finds
// that point by a linear scan. `max_chunk_duration_ns` and `sync_each_chunk`
// bound how much log time a power loss can take.
//
// Not thread-safe: one writer thread owns the object. Messages are buffered
// into a reused chunk buffer, so steady-state writing does not allocate per
// message (only per chunk, for its index entry).

#include <cstddef>
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/log/mcap/compression.h"
#include "core/log/mcap/mcap_format.h"
#include "core/log/mcap/mcap_types.h"

namespace rover::log {

struct McapWriterOptions {
  std::string profile = "ros2";
  std::string library = "rover_log";
  Compression compression = Compression::kZstd;
  int zstd_level = 1;
  /// Close a chunk once its uncompressed records reach this size.
  uint64_t chunk_size_bytes = 1 << 20;
  /// Or once its messages span this much log time (bounds what power loss can
  /// lose). Zero or negative disables the limit.
  int64_t max_chunk_duration_ns = 500'000'000;
  /// fdatasync(2) after each chunk, so a completed chunk survives power loss.
  bool sync_each_chunk = false;
};

/// What the writer has produced so far.
struct McapStats {
  uint64_t messages = 0;            ///< Messages accepted (including the open chunk's).
  uint64_t chunks = 0;              ///< Chunks written.
  uint64_t bytes_written = 0;       ///< Bytes written to the file.
  uint64_t uncompressed_bytes = 0;  ///< Sum of written chunks' uncompressed record sizes.
  uint64_t compressed_bytes = 0;    ///< Sum of written chunks' stored record sizes.
  uint32_t schemas = 0;
  uint32_t channels = 0;
  uint32_t metadata = 0;
  uint32_t attachments = 0;
};

class McapWriter {
 public:
  /// Throws McapError if the options are invalid (e.g. zstd level out of range).
  explicit McapWriter(McapWriterOptions options = {});
  /// Closes the file if it is still open; errors are swallowed (call Close()
  /// to see them).
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  /// Creates (truncates) `path` and writes the magic and Header record.
  /// Throws McapError with the path and errno text on failure, or if a file
  /// is already open. A closed writer may be reopened on a new path.
  void Open(const std::string& path);
  bool is_open() const { return fd_ >= 0; }

  /// Writes a Schema record into the data section at once and returns its id
  /// (1, 2, ...). Adding an identical schema again returns the existing id.
  uint16_t AddSchema(std::string_view name, std::string_view encoding,
                     std::span<const std::byte> data);
  /// As AddSchema() with a caller-chosen id, for tools that copy files.
  /// Throws McapError if `id` is 0 or already used.
  void AddSchemaWithId(uint16_t id, std::string_view name, std::string_view encoding,
                       std::span<const std::byte> data);
  /// Writes a Channel record into the data section at once and returns its id
  /// (1, 2, ...). `schema_id` must be 0 (no schema) or a known schema.
  /// Adding an identical channel again returns the existing id.
  uint16_t AddChannel(uint16_t schema_id, std::string_view topic, std::string_view message_encoding,
                      const std::map<std::string, std::string>& metadata = {});
  /// As AddChannel() with a caller-chosen id. Throws McapError if `id` is used.
  void AddChannelWithId(uint16_t id, uint16_t schema_id, std::string_view topic,
                        std::string_view message_encoding,
                        const std::map<std::string, std::string>& metadata = {});

  /// Appends a message to the open chunk; closes the chunk (see FlushChunk())
  /// when it reaches the size or duration limit. Throws McapError for an
  /// unknown channel or an I/O error.
  void WriteMessage(uint16_t channel_id, uint32_t sequence, uint64_t log_time_ns,
                    uint64_t publish_time_ns, std::span<const std::byte> data);
  /// Writes a Metadata record into the data section at once.
  void WriteMetadata(std::string_view name, const std::map<std::string, std::string>& metadata);
  /// Writes an Attachment record (with its CRC) into the data section at once.
  void WriteAttachment(std::string_view name, std::string_view media_type, uint64_t log_time_ns,
                       uint64_t create_time_ns, std::span<const std::byte> data);

  /// Closes the open chunk now: compresses it and writes the Chunk and its
  /// Message Index records with a single write(2) (then fdatasync if
  /// `sync_each_chunk`). Does nothing when the chunk is empty.
  void FlushChunk();
  /// Flushes the open chunk, writes Data End, the summary, the summary
  /// offsets, the Footer and the closing magic, syncs and closes the file.
  /// Does nothing if no file is open. Throws McapError on I/O failure.
  void Close();

  const McapStats& stats() const { return stats_; }
  const McapWriterOptions& options() const { return options_; }

 private:
  struct IndexEntry {
    uint64_t log_time;
    uint64_t offset;
  };
  struct ChannelState {
    Channel channel;
    uint64_t message_count = 0;
    std::vector<IndexEntry> chunk_index;  // This chunk's entries; capacity kept.
  };

  void CheckWritable(const char* what) const;
  void AddSchemaRecord(Schema schema);
  void AddChannelRecord(Channel channel);
  /// Writes all of `bytes` at the current offset (one write(2) unless the
  /// kernel writes partially), updating the offset and data section CRC.
  void WriteOut(std::span<const std::byte> bytes, bool data_section);
  void CloseFd();

  McapWriterOptions options_;
  internal::ChunkCompressor compressor_;
  std::string path_;
  int fd_ = -1;
  bool failed_ = false;  // A write failed; the file ends at its last complete record.
  uint64_t offset_ = 0;
  uint32_t data_crc_ = 0;

  std::map<uint16_t, Schema> schemas_;
  std::map<uint16_t, ChannelState> channels_;
  uint16_t next_schema_id_ = 1;
  uint16_t next_channel_id_ = 1;

  // The open chunk.
  std::vector<std::byte> chunk_records_;
  std::vector<uint16_t> chunk_channels_;  // Channels with messages in the open chunk.
  uint64_t chunk_messages_ = 0;
  uint64_t chunk_start_time_ = 0;
  uint64_t chunk_end_time_ = 0;

  std::vector<std::byte> out_;  // Staging buffer for one write(2); capacity kept.
  std::vector<internal::ChunkIndexRecord> chunk_indexes_;
  std::vector<internal::MetadataIndexRecord> metadata_indexes_;
  std::vector<AttachmentInfo> attachment_indexes_;
  uint64_t message_start_time_ = 0;
  uint64_t message_end_time_ = 0;
  McapStats stats_;
};

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_MCAP_MCAP_WRITER_H_
