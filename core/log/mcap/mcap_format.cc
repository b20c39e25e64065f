#include "core/log/mcap/mcap_format.h"

#include <cstdio>
#include <cstring>
#include <limits>

#include "core/log/mcap/crc32.h"

namespace rover::log::internal {

std::string OpcodeName(uint8_t opcode) {
  static constexpr const char* kNames[] = {nullptr,      "Header",           "Footer",
                                           "Schema",     "Channel",          "Message",
                                           "Chunk",      "Message Index",    "Chunk Index",
                                           "Attachment", "Attachment Index", "Statistics",
                                           "Metadata",   "Metadata Index",   "Summary Offset",
                                           "Data End"};
  char hex[8];
  std::snprintf(hex, sizeof(hex), "0x%02x", static_cast<unsigned>(opcode));
  if (opcode >= 1 && opcode <= 0x0F) return std::string(kNames[opcode]) + " (" + hex + ")";
  return hex;
}

std::string Hex32(uint32_t value) {
  char hex[16];
  std::snprintf(hex, sizeof(hex), "0x%08x", static_cast<unsigned>(value));
  return hex;
}

// --- serialisation -----------------------------------------------------------

namespace {

template <typename T>
void PutInt(std::vector<std::byte>& out, T v) {
  const size_t n = out.size();
  out.resize(n + sizeof(T));
  StoreLe(out.data() + n, v);
}

// Starts a uint32 byte-length prefix (maps, arrays); returns where it is.
size_t BeginU32Length(std::vector<std::byte>& out) {
  const size_t at = out.size();
  PutU32(out, 0);
  return at;
}

void EndU32Length(std::vector<std::byte>& out, size_t at) {
  const size_t length = out.size() - at - 4;
  if (length > std::numeric_limits<uint32_t>::max()) {
    throw McapError("MCAP map of " + std::to_string(length) +
                    " bytes exceeds the 4 GiB limit of its uint32 length prefix");
  }
  StoreLe(out.data() + at, static_cast<uint32_t>(length));
}

}  // namespace

void PutU8(std::vector<std::byte>& out, uint8_t v) { out.push_back(static_cast<std::byte>(v)); }
void PutU16(std::vector<std::byte>& out, uint16_t v) { PutInt(out, v); }
void PutU32(std::vector<std::byte>& out, uint32_t v) { PutInt(out, v); }
void PutU64(std::vector<std::byte>& out, uint64_t v) { PutInt(out, v); }

void PutBytes(std::vector<std::byte>& out, std::span<const std::byte> bytes) {
  out.insert(out.end(), bytes.begin(), bytes.end());
}

void PutString(std::vector<std::byte>& out, std::string_view s) {
  if (s.size() > std::numeric_limits<uint32_t>::max()) {
    throw McapError("MCAP string of " + std::to_string(s.size()) +
                    " bytes exceeds the 4 GiB limit of its uint32 length prefix");
  }
  PutU32(out, static_cast<uint32_t>(s.size()));
  PutBytes(out, std::as_bytes(std::span(s.data(), s.size())));
}

void PutStringMap(std::vector<std::byte>& out, const std::map<std::string, std::string>& map) {
  const size_t at = BeginU32Length(out);
  for (const auto& [key, value] : map) {
    PutString(out, key);
    PutString(out, value);
  }
  EndU32Length(out, at);
}

void PutU16U64Map(std::vector<std::byte>& out, const std::map<uint16_t, uint64_t>& map) {
  const size_t at = BeginU32Length(out);
  for (const auto& [key, value] : map) {
    PutU16(out, key);
    PutU64(out, value);
  }
  EndU32Length(out, at);
}

size_t BeginRecord(std::vector<std::byte>& out, Opcode opcode) {
  const size_t start = out.size();
  PutU8(out, static_cast<uint8_t>(opcode));
  PutU64(out, 0);
  return start;
}

void EndRecord(std::vector<std::byte>& out, size_t record_start) {
  const uint64_t length = out.size() - record_start - kRecordPrefixSize;
  StoreLe(out.data() + record_start + 1, length);
}

void AppendHeader(std::vector<std::byte>& out, const Header& header) {
  const size_t r = BeginRecord(out, Opcode::kHeader);
  PutString(out, header.profile);
  PutString(out, header.library);
  EndRecord(out, r);
}

void AppendSchema(std::vector<std::byte>& out, const Schema& schema) {
  if (schema.data.size() > std::numeric_limits<uint32_t>::max()) {
    throw McapError("schema '" + schema.name + "' data of " + std::to_string(schema.data.size()) +
                    " bytes exceeds the 4 GiB limit of its uint32 length prefix");
  }
  const size_t r = BeginRecord(out, Opcode::kSchema);
  PutU16(out, schema.id);
  PutString(out, schema.name);
  PutString(out, schema.encoding);
  PutU32(out, static_cast<uint32_t>(schema.data.size()));
  PutBytes(out, schema.data);
  EndRecord(out, r);
}

void AppendChannel(std::vector<std::byte>& out, const Channel& channel) {
  const size_t r = BeginRecord(out, Opcode::kChannel);
  PutU16(out, channel.id);
  PutU16(out, channel.schema_id);
  PutString(out, channel.topic);
  PutString(out, channel.message_encoding);
  PutStringMap(out, channel.metadata);
  EndRecord(out, r);
}

void AppendMessage(std::vector<std::byte>& out, uint16_t channel_id, uint32_t sequence,
                   uint64_t log_time, uint64_t publish_time, std::span<const std::byte> data) {
  // One resize for the fixed part keeps this cheap; it runs once per message.
  const size_t start = out.size();
  out.resize(start + kRecordPrefixSize + kMessageFixedSize);
  std::byte* p = out.data() + start;
  p[0] = static_cast<std::byte>(Opcode::kMessage);
  StoreLe(p + 1, kMessageFixedSize + data.size());
  StoreLe(p + 9, channel_id);
  StoreLe(p + 11, sequence);
  StoreLe(p + 15, log_time);
  StoreLe(p + 23, publish_time);
  PutBytes(out, data);
}

void AppendMetadata(std::vector<std::byte>& out, const Metadata& metadata) {
  const size_t r = BeginRecord(out, Opcode::kMetadata);
  PutString(out, metadata.name);
  PutStringMap(out, metadata.metadata);
  EndRecord(out, r);
}

void AppendAttachment(std::vector<std::byte>& out, uint64_t log_time, uint64_t create_time,
                      std::string_view name, std::string_view media_type,
                      std::span<const std::byte> data) {
  const size_t r = BeginRecord(out, Opcode::kAttachment);
  PutU64(out, log_time);
  PutU64(out, create_time);
  PutString(out, name);
  PutString(out, media_type);
  PutU64(out, data.size());
  PutBytes(out, data);
  // The CRC covers every field before it, but not the record's opcode and length.
  const size_t body = r + kRecordPrefixSize;
  PutU32(out, Crc32(std::span(out.data() + body, out.size() - body)));
  EndRecord(out, r);
}

void AppendAttachmentIndex(std::vector<std::byte>& out, const AttachmentInfo& info) {
  const size_t r = BeginRecord(out, Opcode::kAttachmentIndex);
  PutU64(out, info.offset);
  PutU64(out, info.length);
  PutU64(out, info.log_time);
  PutU64(out, info.create_time);
  PutU64(out, info.data_size);
  PutString(out, info.name);
  PutString(out, info.media_type);
  EndRecord(out, r);
}

void AppendStatistics(std::vector<std::byte>& out, const Statistics& stats) {
  const size_t r = BeginRecord(out, Opcode::kStatistics);
  PutU64(out, stats.message_count);
  PutU16(out, stats.schema_count);
  PutU32(out, stats.channel_count);
  PutU32(out, stats.attachment_count);
  PutU32(out, stats.metadata_count);
  PutU32(out, stats.chunk_count);
  PutU64(out, stats.message_start_time);
  PutU64(out, stats.message_end_time);
  PutU16U64Map(out, stats.channel_message_counts);
  EndRecord(out, r);
}

void AppendChunkIndex(std::vector<std::byte>& out, const ChunkIndexRecord& index) {
  const size_t r = BeginRecord(out, Opcode::kChunkIndex);
  PutU64(out, index.message_start_time);
  PutU64(out, index.message_end_time);
  PutU64(out, index.chunk_start_offset);
  PutU64(out, index.chunk_length);
  PutU16U64Map(out, index.message_index_offsets);
  PutU64(out, index.message_index_length);
  PutString(out, index.compression);
  PutU64(out, index.compressed_size);
  PutU64(out, index.uncompressed_size);
  EndRecord(out, r);
}

void AppendMetadataIndex(std::vector<std::byte>& out, const MetadataIndexRecord& index) {
  const size_t r = BeginRecord(out, Opcode::kMetadataIndex);
  PutU64(out, index.offset);
  PutU64(out, index.length);
  PutString(out, index.name);
  EndRecord(out, r);
}

void AppendSummaryOffset(std::vector<std::byte>& out, const SummaryOffsetRecord& offset) {
  const size_t r = BeginRecord(out, Opcode::kSummaryOffset);
  PutU8(out, offset.group_opcode);
  PutU64(out, offset.group_start);
  PutU64(out, offset.group_length);
  EndRecord(out, r);
}

void AppendDataEnd(std::vector<std::byte>& out, uint32_t data_section_crc) {
  const size_t r = BeginRecord(out, Opcode::kDataEnd);
  PutU32(out, data_section_crc);
  EndRecord(out, r);
}

// --- parsing -----------------------------------------------------------------

bool ByteReader::Fail(const char* field, uint64_t needed) {
  if (error_.empty()) {
    error_ = std::string("field '") + field + "' needs " + std::to_string(needed) +
             " bytes at byte " + std::to_string(base_ + pos_) + " of the record, but only " +
             std::to_string(remaining()) + " remain";
  }
  return false;
}

bool ByteReader::Take(const char* field, uint64_t n, std::span<const std::byte>* out) {
  if (!ok() || n > remaining()) return Fail(field, n);
  *out = data_.subspan(pos_, static_cast<size_t>(n));
  pos_ += static_cast<size_t>(n);
  return true;
}

bool ByteReader::String(const char* field, std::string_view* out) {
  std::span<const std::byte> bytes;
  if (!Bytes32(field, &bytes)) return false;
  *out = std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  return true;
}

bool ByteReader::String(const char* field, std::string* out) {
  std::string_view view;
  if (!String(field, &view)) return false;
  out->assign(view);
  return true;
}

bool ByteReader::Bytes32(const char* field, std::span<const std::byte>* out) {
  uint32_t n = 0;
  return U32(field, &n) && Take(field, n, out);
}

bool ByteReader::Bytes64(const char* field, std::span<const std::byte>* out) {
  uint64_t n = 0;
  return U64(field, &n) && Take(field, n, out);
}

bool ByteReader::StringMap(const char* field, std::map<std::string, std::string>* out) {
  const uint64_t start = base_ + pos_ + 4;
  std::span<const std::byte> bytes;
  if (!Bytes32(field, &bytes)) return false;
  ByteReader entries(bytes, start);
  out->clear();
  while (entries.remaining() > 0) {
    std::string_view key;
    std::string_view value;
    if (!entries.String(field, &key) || !entries.String(field, &value)) {
      error_ = entries.error();
      return false;
    }
    out->insert_or_assign(std::string(key), std::string(value));
  }
  return true;
}

bool ByteReader::U16U64Map(const char* field, std::map<uint16_t, uint64_t>* out) {
  const uint64_t start = base_ + pos_ + 4;
  std::span<const std::byte> bytes;
  if (!Bytes32(field, &bytes)) return false;
  ByteReader entries(bytes, start);
  out->clear();
  while (entries.remaining() > 0) {
    uint16_t key = 0;
    uint64_t value = 0;
    if (!entries.U16(field, &key) || !entries.U64(field, &value)) {
      error_ = entries.error();
      return false;
    }
    out->insert_or_assign(key, value);
  }
  return true;
}

std::span<const std::byte> ByteReader::Rest() {
  if (!ok()) return {};
  auto rest = data_.subspan(pos_);
  pos_ = data_.size();
  return rest;
}

FrameResult FrameRecord(std::span<const std::byte> data, uint64_t pos, RecordView* record,
                        std::string* error) {
  if (pos >= data.size()) return FrameResult::kEnd;
  const uint64_t left = data.size() - pos;
  if (left < kRecordPrefixSize) {
    *error = "record at offset " + std::to_string(pos) + ": the 9-byte opcode + length prefix" +
             " is cut off after " + std::to_string(left) + " bytes";
    return FrameResult::kTruncated;
  }
  const std::byte* p = data.data() + pos;
  const auto opcode = static_cast<uint8_t>(p[0]);
  const auto length = LoadLe<uint64_t>(p + 1);
  if (length > left - kRecordPrefixSize) {
    *error = OpcodeName(opcode) + " record at offset " + std::to_string(pos) + ": declares " +
             std::to_string(length) + " content bytes, but only " +
             std::to_string(left - kRecordPrefixSize) + " remain in the file";
    return FrameResult::kTruncated;
  }
  record->opcode = opcode;
  record->offset = pos;
  record->body =
      data.subspan(static_cast<size_t>(pos + kRecordPrefixSize), static_cast<size_t>(length));
  return FrameResult::kOk;
}

namespace {

bool Finish(const ByteReader& r, std::string* error) {
  if (r.ok()) return true;
  *error = r.error();
  return false;
}

}  // namespace

// Records may gain fields at their end in later spec revisions, so every
// parser below ignores bytes after the fields it knows (except Message, whose
// data is the rest of the record, and Footer, which is fixed-size).

bool ParseHeader(std::span<const std::byte> body, Header* out, std::string* error) {
  ByteReader r(body);
  r.String("profile", &out->profile);
  r.String("library", &out->library);
  return Finish(r, error);
}

bool ParseFooter(std::span<const std::byte> body, FooterRecord* out, std::string* error) {
  if (body.size() != kFooterBodySize) {
    *error = "Footer content must be " + std::to_string(kFooterBodySize) + " bytes, found " +
             std::to_string(body.size());
    return false;
  }
  ByteReader r(body);
  r.U64("summary_start", &out->summary_start);
  r.U64("summary_offset_start", &out->summary_offset_start);
  r.U32("summary_crc", &out->summary_crc);
  return Finish(r, error);
}

bool ParseSchema(std::span<const std::byte> body, Schema* out, std::string* error) {
  ByteReader r(body);
  std::span<const std::byte> data;
  r.U16("id", &out->id);
  r.String("name", &out->name);
  r.String("encoding", &out->encoding);
  if (r.Bytes32("data", &data)) out->data.assign(data.begin(), data.end());
  return Finish(r, error);
}

bool ParseChannel(std::span<const std::byte> body, Channel* out, std::string* error) {
  ByteReader r(body);
  r.U16("id", &out->id);
  r.U16("schema_id", &out->schema_id);
  r.String("topic", &out->topic);
  r.String("message_encoding", &out->message_encoding);
  r.StringMap("metadata", &out->metadata);
  return Finish(r, error);
}

bool ParseMessage(std::span<const std::byte> body, MessageRecordView* out, std::string* error) {
  ByteReader r(body);
  r.U16("channel_id", &out->channel_id);
  r.U32("sequence", &out->sequence);
  r.U64("log_time", &out->log_time);
  r.U64("publish_time", &out->publish_time);
  out->data = r.Rest();
  return Finish(r, error);
}

bool ParseChunk(std::span<const std::byte> body, ChunkView* out, std::string* error) {
  ByteReader r(body);
  r.U64("message_start_time", &out->message_start_time);
  r.U64("message_end_time", &out->message_end_time);
  r.U64("uncompressed_size", &out->uncompressed_size);
  r.U32("uncompressed_crc", &out->uncompressed_crc);
  r.String("compression", &out->compression);
  uint64_t n = 0;
  r.U64("records", &n);
  out->records_offset = r.position();
  r.Take("records", n, &out->records);
  return Finish(r, error);
}

bool ParseMessageIndex(std::span<const std::byte> body, MessageIndexView* out, std::string* error) {
  ByteReader r(body);
  r.U16("channel_id", &out->channel_id);
  if (r.Bytes32("records", &out->entries) && out->entries.size() % kMessageIndexEntrySize != 0) {
    *error = "field 'records' is " + std::to_string(out->entries.size()) +
             " bytes, not a multiple of the 16-byte (log_time, offset) entry";
    return false;
  }
  return Finish(r, error);
}

bool ParseChunkIndex(std::span<const std::byte> body, ChunkIndexRecord* out, std::string* error) {
  ByteReader r(body);
  r.U64("message_start_time", &out->message_start_time);
  r.U64("message_end_time", &out->message_end_time);
  r.U64("chunk_start_offset", &out->chunk_start_offset);
  r.U64("chunk_length", &out->chunk_length);
  r.U16U64Map("message_index_offsets", &out->message_index_offsets);
  r.U64("message_index_length", &out->message_index_length);
  r.String("compression", &out->compression);
  r.U64("compressed_size", &out->compressed_size);
  r.U64("uncompressed_size", &out->uncompressed_size);
  return Finish(r, error);
}

bool ParseAttachment(std::span<const std::byte> body, AttachmentView* out, std::string* error) {
  ByteReader r(body);
  r.U64("log_time", &out->log_time);
  r.U64("create_time", &out->create_time);
  r.String("name", &out->name);
  r.String("media_type", &out->media_type);
  r.Bytes64("data", &out->data);
  out->crc_covered = r.position();
  r.U32("crc", &out->crc);
  return Finish(r, error);
}

bool ParseAttachmentIndex(std::span<const std::byte> body, AttachmentInfo* out,
                          std::string* error) {
  ByteReader r(body);
  r.U64("offset", &out->offset);
  r.U64("length", &out->length);
  r.U64("log_time", &out->log_time);
  r.U64("create_time", &out->create_time);
  r.U64("data_size", &out->data_size);
  r.String("name", &out->name);
  r.String("media_type", &out->media_type);
  return Finish(r, error);
}

bool ParseStatistics(std::span<const std::byte> body, Statistics* out, std::string* error) {
  ByteReader r(body);
  r.U64("message_count", &out->message_count);
  r.U16("schema_count", &out->schema_count);
  r.U32("channel_count", &out->channel_count);
  r.U32("attachment_count", &out->attachment_count);
  r.U32("metadata_count", &out->metadata_count);
  r.U32("chunk_count", &out->chunk_count);
  r.U64("message_start_time", &out->message_start_time);
  r.U64("message_end_time", &out->message_end_time);
  r.U16U64Map("channel_message_counts", &out->channel_message_counts);
  return Finish(r, error);
}

bool ParseMetadata(std::span<const std::byte> body, Metadata* out, std::string* error) {
  ByteReader r(body);
  r.String("name", &out->name);
  r.StringMap("metadata", &out->metadata);
  return Finish(r, error);
}

bool ParseMetadataIndex(std::span<const std::byte> body, MetadataIndexRecord* out,
                        std::string* error) {
  ByteReader r(body);
  r.U64("offset", &out->offset);
  r.U64("length", &out->length);
  r.String("name", &out->name);
  return Finish(r, error);
}

bool ParseSummaryOffset(std::span<const std::byte> body, SummaryOffsetRecord* out,
                        std::string* error) {
  ByteReader r(body);
  r.U8("group_opcode", &out->group_opcode);
  r.U64("group_start", &out->group_start);
  r.U64("group_length", &out->group_length);
  return Finish(r, error);
}

bool ParseDataEnd(std::span<const std::byte> body, uint32_t* data_section_crc, std::string* error) {
  ByteReader r(body);
  r.U32("data_section_crc", data_section_crc);
  return Finish(r, error);
}

}  // namespace rover::log::internal
