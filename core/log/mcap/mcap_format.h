#ifndef ROVER_CORE_LOG_MCAP_MCAP_FORMAT_H_
#define ROVER_CORE_LOG_MCAP_MCAP_FORMAT_H_

// Internal to core/log/mcap: the MCAP wire format (https://mcap.dev/spec).
// Record serialisers used by the writer, and bounds-checked parsers used by
// the reader. Every parser takes a record body and reports, on failure, which
// field did not fit and how many bytes were needed and left.

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/log/mcap/mcap_types.h"

namespace rover::log::internal {

inline constexpr std::array<std::byte, 8> kMagic = {std::byte{0x89}, std::byte{'M'}, std::byte{'C'},
                                                    std::byte{'A'},  std::byte{'P'}, std::byte{'0'},
                                                    std::byte{'\r'}, std::byte{'\n'}};

enum class Opcode : uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kAttachment = 0x09,
  kAttachmentIndex = 0x0A,
  kStatistics = 0x0B,
  kMetadata = 0x0C,
  kMetadataIndex = 0x0D,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

/// Opcode byte + uint64 content length in front of every record.
inline constexpr uint64_t kRecordPrefixSize = 9;
/// Footer content: summary_start u64, summary_offset_start u64, summary_crc u32.
inline constexpr uint64_t kFooterBodySize = 20;
inline constexpr uint64_t kFooterRecordSize = kRecordPrefixSize + kFooterBodySize;
/// Footer bytes covered by summary_crc: opcode, length, summary_start, summary_offset_start.
inline constexpr uint64_t kFooterCrcPrefixSize = kRecordPrefixSize + 16;
inline constexpr uint64_t kDataEndRecordSize = kRecordPrefixSize + 4;
/// Fixed part of a Message record before its data.
inline constexpr uint64_t kMessageFixedSize = 2 + 4 + 8 + 8;
/// Size of one (log_time, offset) entry of a Message Index record.
inline constexpr uint64_t kMessageIndexEntrySize = 16;

/// "Chunk (0x06)" for known opcodes, "0x46" otherwise.
std::string OpcodeName(uint8_t opcode);
/// "0x1234abcd".
std::string Hex32(uint32_t value);

// --- little-endian helpers -------------------------------------------------

template <typename T>
inline void StoreLe(std::byte* p, T value) {
  uint64_t v = value;
  for (size_t i = 0; i < sizeof(T); ++i) {
    p[i] = static_cast<std::byte>(v & 0xFFU);
    v >>= 8;
  }
}

template <typename T>
inline T LoadLe(const std::byte* p) {
  uint64_t v = 0;
  for (size_t i = 0; i < sizeof(T); ++i) {
    v |= static_cast<uint64_t>(p[i]) << (8 * i);
  }
  return static_cast<T>(v);
}

// --- serialisation -----------------------------------------------------------

void PutU8(std::vector<std::byte>& out, uint8_t v);
void PutU16(std::vector<std::byte>& out, uint16_t v);
void PutU32(std::vector<std::byte>& out, uint32_t v);
void PutU64(std::vector<std::byte>& out, uint64_t v);
void PutBytes(std::vector<std::byte>& out, std::span<const std::byte> bytes);
/// uint32 length + bytes. Throws McapError above 4 GiB.
void PutString(std::vector<std::byte>& out, std::string_view s);
/// uint32 byte length + (String key, String value) entries.
void PutStringMap(std::vector<std::byte>& out, const std::map<std::string, std::string>& map);
/// uint32 byte length + (uint16 key, uint64 value) entries.
void PutU16U64Map(std::vector<std::byte>& out, const std::map<uint16_t, uint64_t>& map);

/// Appends the opcode and a placeholder length; returns the record's start index in `out`.
size_t BeginRecord(std::vector<std::byte>& out, Opcode opcode);
/// Patches the length of the record that BeginRecord() started at `record_start`.
void EndRecord(std::vector<std::byte>& out, size_t record_start);

struct ChunkIndexRecord {
  uint64_t message_start_time = 0;
  uint64_t message_end_time = 0;
  uint64_t chunk_start_offset = 0;
  uint64_t chunk_length = 0;
  std::map<uint16_t, uint64_t> message_index_offsets;
  uint64_t message_index_length = 0;
  std::string compression;
  uint64_t compressed_size = 0;
  uint64_t uncompressed_size = 0;
  bool operator==(const ChunkIndexRecord&) const = default;
};

struct MetadataIndexRecord {
  uint64_t offset = 0;
  uint64_t length = 0;
  std::string name;
};

struct SummaryOffsetRecord {
  uint8_t group_opcode = 0;
  uint64_t group_start = 0;
  uint64_t group_length = 0;
};

struct FooterRecord {
  uint64_t summary_start = 0;
  uint64_t summary_offset_start = 0;
  uint32_t summary_crc = 0;
};

void AppendHeader(std::vector<std::byte>& out, const Header& header);
void AppendSchema(std::vector<std::byte>& out, const Schema& schema);
void AppendChannel(std::vector<std::byte>& out, const Channel& channel);
void AppendMessage(std::vector<std::byte>& out, uint16_t channel_id, uint32_t sequence,
                   uint64_t log_time, uint64_t publish_time, std::span<const std::byte> data);
void AppendMetadata(std::vector<std::byte>& out, const Metadata& metadata);
/// Attachment record with its trailing CRC over all preceding fields.
void AppendAttachment(std::vector<std::byte>& out, uint64_t log_time, uint64_t create_time,
                      std::string_view name, std::string_view media_type,
                      std::span<const std::byte> data);
void AppendAttachmentIndex(std::vector<std::byte>& out, const AttachmentInfo& info);
void AppendStatistics(std::vector<std::byte>& out, const Statistics& stats);
void AppendChunkIndex(std::vector<std::byte>& out, const ChunkIndexRecord& index);
void AppendMetadataIndex(std::vector<std::byte>& out, const MetadataIndexRecord& index);
void AppendSummaryOffset(std::vector<std::byte>& out, const SummaryOffsetRecord& offset);
void AppendDataEnd(std::vector<std::byte>& out, uint32_t data_section_crc);

// --- parsing -----------------------------------------------------------------

/// Bounds-checked little-endian cursor over a record body. After the first
/// failed read every later read fails too, and error() says which field did
/// not fit, at which byte of the record, how many bytes it needed and how many
/// were left.
class ByteReader {
 public:
  /// `base` is the position of data[0] within the record body, for messages.
  explicit ByteReader(std::span<const std::byte> data, uint64_t base = 0)
      : data_(data), base_(base) {}

  bool U8(const char* field, uint8_t* v) { return Int(field, v); }
  bool U16(const char* field, uint16_t* v) { return Int(field, v); }
  bool U32(const char* field, uint32_t* v) { return Int(field, v); }
  bool U64(const char* field, uint64_t* v) { return Int(field, v); }
  /// The next `n` bytes.
  bool Take(const char* field, uint64_t n, std::span<const std::byte>* out);
  /// uint32 length-prefixed string (not checked for UTF-8).
  bool String(const char* field, std::string_view* out);
  bool String(const char* field, std::string* out);
  /// uint32 length-prefixed bytes.
  bool Bytes32(const char* field, std::span<const std::byte>* out);
  /// uint64 length-prefixed bytes.
  bool Bytes64(const char* field, std::span<const std::byte>* out);
  bool StringMap(const char* field, std::map<std::string, std::string>* out);
  bool U16U64Map(const char* field, std::map<uint16_t, uint64_t>* out);
  /// Everything not read yet.
  std::span<const std::byte> Rest();

  uint64_t position() const { return pos_; }
  uint64_t remaining() const { return data_.size() - pos_; }
  bool ok() const { return error_.empty(); }
  const std::string& error() const { return error_; }

 private:
  template <typename T>
  bool Int(const char* field, T* v) {
    if (!ok() || remaining() < sizeof(T)) return Fail(field, sizeof(T));
    *v = LoadLe<T>(data_.data() + pos_);
    pos_ += sizeof(T);
    return true;
  }
  bool Fail(const char* field, uint64_t needed);

  std::span<const std::byte> data_;
  uint64_t base_ = 0;
  size_t pos_ = 0;
  std::string error_;
};

/// One record as framed in the file: opcode, content, and where it starts.
struct RecordView {
  uint8_t opcode = 0;
  uint64_t offset = 0;  ///< Offset of the opcode byte within the parsed span.
  std::span<const std::byte> body;
  uint64_t size() const { return kRecordPrefixSize + body.size(); }
};

enum class FrameResult { kOk, kEnd, kTruncated };

/// Frames the record at `pos` of `data`. kEnd when pos == data.size();
/// kTruncated (with `error` set) when the prefix or the content does not fit.
FrameResult FrameRecord(std::span<const std::byte> data, uint64_t pos, RecordView* record,
                        std::string* error);

struct ChunkView {
  uint64_t message_start_time = 0;
  uint64_t message_end_time = 0;
  uint64_t uncompressed_size = 0;
  uint32_t uncompressed_crc = 0;
  std::string_view compression;
  std::span<const std::byte> records;
  uint64_t records_offset = 0;  ///< Offset of `records` within the record body.
};

struct MessageRecordView {
  uint16_t channel_id = 0;
  uint32_t sequence = 0;
  uint64_t log_time = 0;
  uint64_t publish_time = 0;
  std::span<const std::byte> data;
};

struct MessageIndexView {
  uint16_t channel_id = 0;
  std::span<const std::byte> entries;  ///< 16-byte (log_time, offset) pairs.
  size_t count() const { return entries.size() / kMessageIndexEntrySize; }
  uint64_t log_time(size_t i) const { return LoadLe<uint64_t>(&entries[16 * i]); }
  uint64_t offset(size_t i) const { return LoadLe<uint64_t>(&entries[16 * i + 8]); }
};

struct AttachmentView {
  uint64_t log_time = 0;
  uint64_t create_time = 0;
  std::string_view name;
  std::string_view media_type;
  std::span<const std::byte> data;
  uint32_t crc = 0;
  uint64_t crc_covered = 0;  ///< Body bytes before the crc field (what the CRC covers).
};

// Each parser reads a record body; on failure it returns false and sets `error`.
bool ParseHeader(std::span<const std::byte> body, Header* out, std::string* error);
bool ParseFooter(std::span<const std::byte> body, FooterRecord* out, std::string* error);
bool ParseSchema(std::span<const std::byte> body, Schema* out, std::string* error);
bool ParseChannel(std::span<const std::byte> body, Channel* out, std::string* error);
bool ParseMessage(std::span<const std::byte> body, MessageRecordView* out, std::string* error);
bool ParseChunk(std::span<const std::byte> body, ChunkView* out, std::string* error);
bool ParseMessageIndex(std::span<const std::byte> body, MessageIndexView* out, std::string* error);
bool ParseChunkIndex(std::span<const std::byte> body, ChunkIndexRecord* out, std::string* error);
bool ParseAttachment(std::span<const std::byte> body, AttachmentView* out, std::string* error);
bool ParseAttachmentIndex(std::span<const std::byte> body, AttachmentInfo* out, std::string* error);
bool ParseStatistics(std::span<const std::byte> body, Statistics* out, std::string* error);
bool ParseMetadata(std::span<const std::byte> body, Metadata* out, std::string* error);
bool ParseMetadataIndex(std::span<const std::byte> body, MetadataIndexRecord* out,
                        std::string* error);
bool ParseSummaryOffset(std::span<const std::byte> body, SummaryOffsetRecord* out,
                        std::string* error);
bool ParseDataEnd(std::span<const std::byte> body, uint32_t* data_section_crc, std::string* error);

}  // namespace rover::log::internal

#endif  // ROVER_CORE_LOG_MCAP_MCAP_FORMAT_H_
