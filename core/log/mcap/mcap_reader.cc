#include "core/log/mcap/mcap_reader.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <limits>
#include <system_error>
#include <utility>

#include "core/log/mcap/compression.h"
#include "core/log/mcap/crc32.h"
#include "core/log/mcap/mcap_format.h"

namespace rover::log {
namespace {

using internal::ByteBuffer;
using internal::ChunkIndexRecord;
using internal::ChunkView;
using internal::FrameRecord;
using internal::FrameResult;
using internal::Hex32;
using internal::MessageIndexView;
using internal::MessageRecordView;
using internal::Opcode;
using internal::OpcodeName;
using internal::RecordView;

std::string ErrnoText(int err) { return std::error_code(err, std::generic_category()).message(); }
std::string Str(uint64_t v) { return std::to_string(v); }

// The file's bytes: a read-only private mapping of the file, or an owned copy.
class Storage {
 public:
  Storage() = default;
  Storage(const Storage&) = delete;
  Storage& operator=(const Storage&) = delete;
  ~Storage() {
    if (map_ != nullptr) ::munmap(map_, map_size_);
  }

  static std::unique_ptr<Storage> MapFile(const std::string& path) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) throw McapError("cannot open MCAP file " + path + ": " + ErrnoText(errno));
    auto storage = std::make_unique<Storage>();
    struct stat st {};
    if (::fstat(fd, &st) != 0) {
      const int err = errno;
      ::close(fd);
      throw McapError("cannot stat MCAP file " + path + ": " + ErrnoText(err));
    }
    if (st.st_size > 0) {
      const auto size = static_cast<uint64_t>(st.st_size);
      if (size > std::numeric_limits<size_t>::max()) {
        ::close(fd);
        throw McapError("MCAP file " + path + " (" + Str(size) +
                        " bytes) is too large to map on this platform");
      }
      void* p = ::mmap(nullptr, static_cast<size_t>(size), PROT_READ, MAP_PRIVATE, fd, 0);
      if (p == reinterpret_cast<void*>(intptr_t{-1})) {  // MAP_FAILED
        const int err = errno;
        ::close(fd);
        throw McapError("cannot map MCAP file " + path + ": " + ErrnoText(err));
      }
      storage->map_ = p;
      storage->map_size_ = static_cast<size_t>(size);
    }
    ::close(fd);
    return storage;
  }

  static std::unique_ptr<Storage> Copy(std::span<const std::byte> bytes) {
    auto storage = std::make_unique<Storage>();
    storage->owned_.assign(bytes.begin(), bytes.end());
    return storage;
  }

  std::span<const std::byte> bytes() const {
    if (map_ != nullptr) return {static_cast<const std::byte*>(map_), map_size_};
    return owned_;
  }

 private:
  void* map_ = nullptr;
  size_t map_size_ = 0;
  std::vector<std::byte> owned_;
};

// A Message record found in decoded chunk records (or in the data section).
struct LocatedMessage {
  uint64_t offset = 0;  // Within the chunk's uncompressed records (or the file).
  MessageRecordView message;
};

struct MetadataEntry {
  uint64_t offset = 0;
  Metadata metadata;
};

// What a record-by-record walk of the data section found.
struct ScanResult {
  std::map<uint16_t, Schema> schemas;
  std::map<uint16_t, Channel> channels;
  std::map<uint16_t, uint64_t> channel_offsets;
  std::vector<MetadataEntry> metadata;
  std::vector<AttachmentInfo> attachments;
  std::vector<ChunkInfo> chunks;
  std::vector<uint64_t> loose_messages;  // Offsets of Message records outside chunks.
  std::vector<std::pair<uint64_t, uint8_t>> odd_records;  // Opcodes not expected here.
  std::optional<uint64_t> data_end_offset;
  uint32_t data_section_crc = 0;
  bool reached_footer = false;  // Found a Footer where Data End was expected.
  bool hit_eof = false;         // Data ran out before Data End: truncated.
  std::vector<Damage> damage;
};

// The summary section as found at Open(), whether or not the reader uses it.
struct SummaryState {
  bool present = false;  // The footer points at a summary section.
  bool ok = false;       // It passed every check.
  std::map<uint16_t, Schema> schemas;
  std::map<uint16_t, Channel> channels;
  std::optional<Statistics> statistics;
  std::vector<ChunkIndexRecord> chunk_indexes;
  std::vector<ChunkInfo> chunks;
  std::vector<Metadata> metadata;
  std::vector<AttachmentInfo> attachments;
};

bool IsKnownCompression(std::string_view c) { return c.empty() || c == "zstd" || c == "lz4"; }

template <typename Record>
void AddUnique(std::map<uint16_t, Record>& map, Record record, uint64_t offset, const char* what,
               std::vector<Damage>* damage) {
  const uint16_t id = record.id;
  // try_emplace leaves `record` untouched when the id exists, for the comparison.
  const auto [it, inserted] = map.try_emplace(id, std::move(record));
  if (!inserted && !(it->second == record) && damage != nullptr) {
    damage->push_back(
        {offset, std::string(what) + " record at offset " + Str(offset) + ": id " + Str(id) +
                     " differs from an earlier record with that id (kept the first)"});
  }
}

}  // namespace

struct McapReader::Impl {
  std::string name;
  std::unique_ptr<Storage> storage;
  std::span<const std::byte> bytes;
  Header header;
  uint64_t header_end = 0;
  bool footer_ok = false;
  uint64_t footer_offset = 0;
  internal::FooterRecord footer;
  SummaryState summary;
  std::vector<Damage> summary_damage;

  bool use_summary = false;  // Indexing from the summary (summary.ok and allowed).
  std::map<uint16_t, Schema> schemas;
  std::map<uint16_t, Channel> channels;
  std::vector<Metadata> metadata;
  std::vector<AttachmentInfo> attachments;
  std::optional<Statistics> statistics;
  std::vector<ChunkInfo> chunks;
  std::vector<uint64_t> loose_messages;
  std::vector<Damage> damage;

  internal::ChunkDecompressor decompressor;
  ByteBuffer scratch;
  std::vector<LocatedMessage> scratch_messages;

  void Init(const OpenOptions& options);
  void LoadFooter();
  void LoadSummary();
  bool ChunkFromIndex(const ChunkIndexRecord& index, ChunkInfo* info, std::string* error) const;
  ScanResult Scan() const;
  void AddTailDamage(const ScanResult& scan, std::vector<Damage>* out) const;
  uint64_t Resync(uint64_t from) const;
  bool DecodeChunk(const ChunkInfo& chunk, internal::ChunkDecompressor* codec, ByteBuffer* buffer,
                   std::vector<LocatedMessage>* messages, std::map<uint16_t, Schema>* found_schemas,
                   std::map<uint16_t, Channel>* found_channels, std::string* error) const;
  // DecodeChunk for iteration: updates the chunk's status and damage().
  bool LoadChunk(ChunkInfo& chunk, ByteBuffer* buffer, std::vector<LocatedMessage>* messages);
  bool MessageAt(uint64_t offset, MessageRecordView* message) const;
  void ForEachInFileOrder(const std::function<bool(const MessageView&)>& fn,
                          const ReadOptions& options);
  void ForEachInLogTimeOrder(const std::function<bool(const MessageView&)>& fn,
                             const ReadOptions& options);
  bool CheckAttachment(const AttachmentInfo& info, std::span<const std::byte>* data,
                       std::string* error) const;
  VerifyReport Verify();
};

// --- opening -----------------------------------------------------------------

void McapReader::Impl::Init(const OpenOptions& options) {
  const auto& magic = internal::kMagic;
  if (bytes.size() < magic.size()) {
    throw McapError(name + ": " + Str(bytes.size()) +
                    " bytes is too short for the 8-byte MCAP magic; not an MCAP file");
  }
  if (!std::equal(magic.begin(), magic.end(), bytes.begin())) {
    throw McapError(name + ": does not start with the MCAP magic \\x89MCAP0\\r\\n");
  }
  RecordView record;
  std::string error;
  switch (FrameRecord(bytes, magic.size(), &record, &error)) {
    case FrameResult::kEnd:
      throw McapError(name + ": file ends after the magic, before the Header record");
    case FrameResult::kTruncated:
      throw McapError(name + ": incomplete Header record: " + error);
    case FrameResult::kOk:
      break;
  }
  if (record.opcode != static_cast<uint8_t>(Opcode::kHeader)) {
    throw McapError(name + ": expected a Header record (0x01) at offset 8, found " +
                    OpcodeName(record.opcode));
  }
  if (!internal::ParseHeader(record.body, &header, &error)) {
    throw McapError(name + ": Header record at offset 8: " + error);
  }
  header_end = magic.size() + record.size();

  LoadFooter();
  LoadSummary();
  damage = summary_damage;
  if (options.use_summary && summary.ok) {
    use_summary = true;
    schemas = summary.schemas;
    channels = summary.channels;
    statistics = summary.statistics;
    chunks = summary.chunks;
    metadata = summary.metadata;
    attachments = summary.attachments;
    return;
  }
  ScanResult scan = Scan();
  schemas = std::move(scan.schemas);
  channels = std::move(scan.channels);
  for (auto& entry : scan.metadata) metadata.push_back(std::move(entry.metadata));
  attachments = std::move(scan.attachments);
  chunks = std::move(scan.chunks);
  loose_messages = std::move(scan.loose_messages);
  damage.insert(damage.end(), scan.damage.begin(), scan.damage.end());
  AddTailDamage(scan, &damage);
}

void McapReader::Impl::AddTailDamage(const ScanResult& scan, std::vector<Damage>* out) const {
  // A cut inside the summary or footer loses no data, but it is still a cut.
  if (!footer_ok && scan.data_end_offset) {
    out->push_back({bytes.size(), "file ends at offset " + Str(bytes.size()) +
                                      " without a Footer record and closing magic: truncated "
                                      "after the data section"});
  }
}

void McapReader::Impl::LoadFooter() {
  const uint64_t size = bytes.size();
  const uint64_t tail = internal::kFooterRecordSize + internal::kMagic.size();
  if (size < header_end + tail) return;
  const uint64_t at = size - tail;
  const auto& magic = internal::kMagic;
  if (!std::equal(magic.begin(), magic.end(), bytes.end() - static_cast<ptrdiff_t>(magic.size()))) {
    return;
  }
  RecordView record;
  std::string error;
  if (FrameRecord(bytes.first(static_cast<size_t>(size - magic.size())), at, &record, &error) !=
          FrameResult::kOk ||
      record.opcode != static_cast<uint8_t>(Opcode::kFooter) ||
      !internal::ParseFooter(record.body, &footer, &error)) {
    return;
  }
  footer_ok = true;
  footer_offset = at;
}

void McapReader::Impl::LoadSummary() {
  if (!footer_ok || footer.summary_start == 0) return;  // No summary is not damage.
  summary.present = true;
  const auto fail = [&](uint64_t offset, const std::string& what) {
    summary_damage.push_back({offset, "summary: " + what + "; using a linear scan instead"});
    summary = SummaryState{};
    summary.present = true;
  };
  const uint64_t start = footer.summary_start;
  const uint64_t offsets_start = footer.summary_offset_start;
  if (start < header_end || start > footer_offset) {
    return fail(footer_offset, "Footer summary_start " + Str(start) + " is outside [" +
                                   Str(header_end) + ", " + Str(footer_offset) + "]");
  }
  if (offsets_start != 0 && (offsets_start < start || offsets_start > footer_offset)) {
    return fail(footer_offset, "Footer summary_offset_start " + Str(offsets_start) +
                                   " is outside [" + Str(start) + ", " + Str(footer_offset) + "]");
  }
  if (footer.summary_crc != 0) {
    const uint64_t end = footer_offset + internal::kFooterCrcPrefixSize;
    const uint32_t crc =
        Crc32(bytes.subspan(static_cast<size_t>(start), static_cast<size_t>(end - start)));
    if (crc != footer.summary_crc) {
      return fail(start, "CRC mismatch over bytes [" + Str(start) + ", " + Str(end) +
                             ") (expected " + Hex32(footer.summary_crc) + ", found " + Hex32(crc) +
                             ")");
    }
  }
  const uint64_t end = offsets_start != 0 ? offsets_start : footer_offset;
  const auto section = bytes.first(static_cast<size_t>(end));
  std::vector<internal::MetadataIndexRecord> metadata_indexes;
  std::string error;
  for (uint64_t pos = start; pos < end;) {
    RecordView record;
    if (FrameRecord(section, pos, &record, &error) != FrameResult::kOk) return fail(pos, error);
    bool parsed = true;
    switch (static_cast<Opcode>(record.opcode)) {
      case Opcode::kSchema: {
        Schema schema;
        parsed = internal::ParseSchema(record.body, &schema, &error);
        if (parsed && schema.id != 0)
          AddUnique(summary.schemas, std::move(schema), pos, "Schema", nullptr);
        break;
      }
      case Opcode::kChannel: {
        Channel channel;
        parsed = internal::ParseChannel(record.body, &channel, &error);
        if (parsed) AddUnique(summary.channels, std::move(channel), pos, "Channel", nullptr);
        break;
      }
      case Opcode::kStatistics: {
        if (summary.statistics) return fail(pos, "second Statistics record at offset " + Str(pos));
        Statistics stats;
        parsed = internal::ParseStatistics(record.body, &stats, &error);
        if (parsed) summary.statistics = std::move(stats);
        break;
      }
      case Opcode::kChunkIndex: {
        ChunkIndexRecord index;
        parsed = internal::ParseChunkIndex(record.body, &index, &error);
        if (parsed) summary.chunk_indexes.push_back(std::move(index));
        break;
      }
      case Opcode::kMetadataIndex: {
        internal::MetadataIndexRecord index;
        parsed = internal::ParseMetadataIndex(record.body, &index, &error);
        if (parsed) metadata_indexes.push_back(std::move(index));
        break;
      }
      case Opcode::kAttachmentIndex: {
        AttachmentInfo info;
        parsed = internal::ParseAttachmentIndex(record.body, &info, &error);
        if (parsed) summary.attachments.push_back(std::move(info));
        break;
      }
      default:
        break;  // Unknown or unexpected records are skipped, as the spec asks.
    }
    if (!parsed)
      return fail(pos, OpcodeName(record.opcode) + " record at offset " + Str(pos) + ": " + error);
    pos += record.size();
  }
  if (offsets_start != 0) {
    const auto offsets = bytes.first(static_cast<size_t>(footer_offset));
    for (uint64_t pos = offsets_start; pos < footer_offset;) {
      RecordView record;
      if (FrameRecord(offsets, pos, &record, &error) != FrameResult::kOk) {
        return fail(pos, error);
      }
      pos += record.size();
    }
  }

  // Everything the summary points at must be a real record of the data section.
  const auto data = bytes.first(static_cast<size_t>(start));
  for (const ChunkIndexRecord& index : summary.chunk_indexes) {
    ChunkInfo info;
    if (!ChunkFromIndex(index, &info, &error)) return fail(index.chunk_start_offset, error);
    summary.chunks.push_back(std::move(info));
  }
  std::sort(summary.chunks.begin(), summary.chunks.end(),
            [](const ChunkInfo& a, const ChunkInfo& b) { return a.offset < b.offset; });
  for (size_t i = 1; i < summary.chunks.size(); ++i) {
    const ChunkInfo& prev = summary.chunks[i - 1];
    if (summary.chunks[i].offset < prev.offset + prev.length) {
      return fail(summary.chunks[i].offset, "chunk indexes for offsets " + Str(prev.offset) +
                                                " and " + Str(summary.chunks[i].offset) +
                                                " overlap");
    }
  }
  for (const auto& index : metadata_indexes) {
    RecordView record;
    Metadata found;
    if (FrameRecord(data, index.offset, &record, &error) != FrameResult::kOk ||
        record.opcode != static_cast<uint8_t>(Opcode::kMetadata) || record.size() != index.length ||
        !internal::ParseMetadata(record.body, &found, &error)) {
      return fail(index.offset, "Metadata Index '" + index.name + "' points at offset " +
                                    Str(index.offset) + " (length " + Str(index.length) +
                                    "), which does not hold a matching Metadata record");
    }
    summary.metadata.push_back(std::move(found));
  }
  for (const AttachmentInfo& info : summary.attachments) {
    RecordView record;
    internal::AttachmentView view;
    if (FrameRecord(data, info.offset, &record, &error) != FrameResult::kOk ||
        record.opcode != static_cast<uint8_t>(Opcode::kAttachment) ||
        record.size() != info.length || !internal::ParseAttachment(record.body, &view, &error) ||
        view.name != info.name || view.data.size() != info.data_size) {
      return fail(info.offset, "Attachment Index '" + info.name + "' points at offset " +
                                   Str(info.offset) + " (length " + Str(info.length) +
                                   "), which does not hold a matching Attachment record");
    }
  }
  summary.ok = true;
}

bool McapReader::Impl::ChunkFromIndex(const ChunkIndexRecord& index, ChunkInfo* info,
                                      std::string* error) const {
  const auto data = bytes.first(static_cast<size_t>(footer.summary_start));
  const std::string where = "Chunk Index for offset " + Str(index.chunk_start_offset);
  RecordView record;
  std::string frame_error;
  if (index.chunk_start_offset < header_end ||
      FrameRecord(data, index.chunk_start_offset, &record, &frame_error) != FrameResult::kOk) {
    *error = where + ": no complete record there in the data section [" + Str(header_end) + ", " +
             Str(data.size()) + ")" + (frame_error.empty() ? "" : ": " + frame_error);
    return false;
  }
  if (record.opcode != static_cast<uint8_t>(Opcode::kChunk)) {
    *error = where + ": expected a Chunk record there, found " + OpcodeName(record.opcode);
    return false;
  }
  if (record.size() != index.chunk_length) {
    *error = where + ": chunk_length is " + Str(index.chunk_length) + ", the record is " +
             Str(record.size()) + " bytes";
    return false;
  }
  ChunkView chunk;
  if (!internal::ParseChunk(record.body, &chunk, error)) {
    *error = where + ": " + *error;
    return false;
  }
  if (chunk.compression != index.compression || chunk.records.size() != index.compressed_size ||
      chunk.uncompressed_size != index.uncompressed_size ||
      chunk.message_start_time != index.message_start_time ||
      chunk.message_end_time != index.message_end_time) {
    *error = where + ": index says compression '" + index.compression + "', " +
             Str(index.compressed_size) + " -> " + Str(index.uncompressed_size) +
             " bytes, times [" + Str(index.message_start_time) + ", " +
             Str(index.message_end_time) + "]; the chunk says '" + std::string(chunk.compression) +
             "', " + Str(chunk.records.size()) + " -> " + Str(chunk.uncompressed_size) +
             " bytes, [" + Str(chunk.message_start_time) + ", " + Str(chunk.message_end_time) + "]";
    return false;
  }
  info->offset = index.chunk_start_offset;
  info->length = index.chunk_length;
  info->message_start_time = chunk.message_start_time;
  info->message_end_time = chunk.message_end_time;
  info->compression = std::string(chunk.compression);
  info->compressed_size = chunk.records.size();
  info->uncompressed_size = chunk.uncompressed_size;
  info->uncompressed_crc = chunk.uncompressed_crc;
  info->message_index_offsets = index.message_index_offsets;
  info->message_index_length = index.message_index_length;
  const uint64_t indexes_start = index.chunk_start_offset + index.chunk_length;
  if (index.message_index_length > data.size() - indexes_start) {
    *error = where + ": message_index_length " + Str(index.message_index_length) +
             " runs past the data section";
    return false;
  }
  const auto indexes = data.first(static_cast<size_t>(indexes_start + index.message_index_length));
  for (const auto& [channel_id, offset] : index.message_index_offsets) {
    MessageIndexView view;
    if (offset < indexes_start ||
        FrameRecord(indexes, offset, &record, &frame_error) != FrameResult::kOk ||
        record.opcode != static_cast<uint8_t>(Opcode::kMessageIndex) ||
        !internal::ParseMessageIndex(record.body, &view, &frame_error) ||
        view.channel_id != channel_id) {
      *error = where + ": message index offset " + Str(offset) + " for channel " + Str(channel_id) +
               " does not hold that channel's Message Index record within [" + Str(indexes_start) +
               ", " + Str(indexes.size()) + ")";
      return false;
    }
    info->message_count += view.count();
  }
  return true;
}

// --- linear scan -------------------------------------------------------------

ScanResult McapReader::Impl::Scan() const {
  ScanResult s;
  bool after_chunk = false;  // The previous record was a chunk or one of its message indexes.
  std::string error;
  uint64_t pos = header_end;
  while (true) {
    RecordView record;
    const FrameResult framed = FrameRecord(bytes, pos, &record, &error);
    if (framed == FrameResult::kEnd) {
      s.damage.push_back({pos, "file ends at offset " + Str(pos) +
                                   " without a Data End record: truncated after the last "
                                   "complete record"});
      s.hit_eof = true;
      break;
    }
    if (framed == FrameResult::kTruncated) {
      const uint64_t next = Resync(pos + 1);
      if (next != 0) {
        s.damage.push_back({pos, error + "; skipped " + Str(next - pos) +
                                     " unreadable bytes up to the next intact-looking chunk at "
                                     "offset " +
                                     Str(next)});
        pos = next;
        after_chunk = false;
        continue;
      }
      s.damage.push_back({pos, error + ": file truncated"});
      s.hit_eof = true;
      break;
    }
    const uint64_t at = pos;
    pos += record.size();
    bool parsed = true;
    bool chunk_related = false;
    bool stop = false;
    switch (static_cast<Opcode>(record.opcode)) {
      case Opcode::kSchema: {
        Schema schema;
        parsed = internal::ParseSchema(record.body, &schema, &error);
        // Schema id 0 is invalid and must be ignored (spec).
        if (parsed && schema.id != 0)
          AddUnique(s.schemas, std::move(schema), at, "Schema", &s.damage);
        break;
      }
      case Opcode::kChannel: {
        Channel channel;
        parsed = internal::ParseChannel(record.body, &channel, &error);
        if (parsed) {
          s.channel_offsets.emplace(channel.id, at);
          AddUnique(s.channels, std::move(channel), at, "Channel", &s.damage);
        }
        break;
      }
      case Opcode::kMessage: {
        MessageRecordView message;
        parsed = internal::ParseMessage(record.body, &message, &error);
        if (parsed) s.loose_messages.push_back(at);
        break;
      }
      case Opcode::kChunk: {
        ChunkView chunk;
        parsed = internal::ParseChunk(record.body, &chunk, &error);
        if (parsed) {
          ChunkInfo info;
          info.offset = at;
          info.length = record.size();
          info.message_start_time = chunk.message_start_time;
          info.message_end_time = chunk.message_end_time;
          info.compression = std::string(chunk.compression);
          info.compressed_size = chunk.records.size();
          info.uncompressed_size = chunk.uncompressed_size;
          info.uncompressed_crc = chunk.uncompressed_crc;
          s.chunks.push_back(std::move(info));
          chunk_related = true;
        }
        break;
      }
      case Opcode::kMessageIndex: {
        MessageIndexView view;
        parsed = internal::ParseMessageIndex(record.body, &view, &error);
        if (parsed && after_chunk) {
          ChunkInfo& chunk = s.chunks.back();
          chunk.message_index_offsets.emplace(view.channel_id, at);
          chunk.message_count += view.count();
          chunk.message_index_length += record.size();
          chunk_related = true;
        } else if (parsed) {
          s.odd_records.emplace_back(at, record.opcode);
        }
        break;
      }
      case Opcode::kMetadata: {
        Metadata found;
        parsed = internal::ParseMetadata(record.body, &found, &error);
        if (parsed) s.metadata.push_back({at, std::move(found)});
        break;
      }
      case Opcode::kAttachment: {
        internal::AttachmentView view;
        parsed = internal::ParseAttachment(record.body, &view, &error);
        if (parsed) {
          s.attachments.push_back({at, record.size(), view.log_time, view.create_time,
                                   std::string(view.name), std::string(view.media_type),
                                   view.data.size()});
        }
        break;
      }
      case Opcode::kDataEnd: {
        parsed = internal::ParseDataEnd(record.body, &s.data_section_crc, &error);
        s.data_end_offset = at;
        stop = true;
        break;
      }
      case Opcode::kFooter:
        // A Footer where Data End belongs: the data section ends here anyway.
        s.reached_footer = true;
        stop = true;
        break;
      case Opcode::kHeader:
        s.damage.push_back({at, "unexpected second Header record at offset " + Str(at)});
        break;
      default:
        // Unknown opcodes are skipped (spec); 0x00 is never valid.
        if (record.opcode == 0) {
          s.damage.push_back({at, "record with invalid opcode 0x00 at offset " + Str(at) + " (" +
                                      Str(record.body.size()) + " bytes, skipped)"});
        } else {
          s.odd_records.emplace_back(at, record.opcode);
        }
        break;
    }
    if (!parsed) {
      s.damage.push_back(
          {at, OpcodeName(record.opcode) + " record at offset " + Str(at) + ": " + error});
    }
    after_chunk = chunk_related;
    if (stop) break;
  }
  return s;
}

// After a record whose length runs past the end of the file, looks for the
// next position from which reading can resume: a Chunk record that frames
// exactly and whose header is self-consistent. Chunk contents are still CRC
// checked before use, so a false match costs nothing but a damage entry.
// Returns 0 when there is none.
uint64_t McapReader::Impl::Resync(uint64_t from) const {
  const uint64_t size = bytes.size();
  const auto* base = bytes.data();
  while (from + internal::kRecordPrefixSize <= size) {
    const void* hit = std::memchr(base + from, static_cast<int>(Opcode::kChunk),
                                  static_cast<size_t>(size - from));
    if (hit == nullptr) return 0;
    const auto q = static_cast<uint64_t>(static_cast<const std::byte*>(hit) - base);
    RecordView record;
    ChunkView chunk;
    std::string error;
    if (FrameRecord(bytes, q, &record, &error) == FrameResult::kOk &&
        internal::ParseChunk(record.body, &chunk, &error) &&
        chunk.records_offset + chunk.records.size() == record.body.size() &&
        IsKnownCompression(chunk.compression) &&
        chunk.message_start_time <= chunk.message_end_time &&
        chunk.uncompressed_size <= internal::kMaxUncompressedChunkSize &&
        (!chunk.compression.empty() || chunk.uncompressed_size == chunk.records.size())) {
      return q;
    }
    from = q + 1;
  }
  return 0;
}

// --- chunks and messages -----------------------------------------------------

bool McapReader::Impl::DecodeChunk(const ChunkInfo& info, internal::ChunkDecompressor* codec,
                                   ByteBuffer* buffer, std::vector<LocatedMessage>* messages,
                                   std::map<uint16_t, Schema>* found_schemas,
                                   std::map<uint16_t, Channel>* found_channels,
                                   std::string* error) const {
  messages->clear();
  RecordView record;
  if (FrameRecord(bytes, info.offset, &record, error) != FrameResult::kOk ||
      record.opcode != static_cast<uint8_t>(Opcode::kChunk)) {
    *error = "no complete Chunk record at this offset";
    return false;
  }
  ChunkView chunk;
  if (!internal::ParseChunk(record.body, &chunk, error)) return false;
  std::span<const std::byte> records;
  if (chunk.compression.empty()) {
    if (chunk.uncompressed_size != chunk.records.size()) {
      *error = "uncompressed chunk declares uncompressed_size " + Str(chunk.uncompressed_size) +
               " but stores " + Str(chunk.records.size()) + " bytes";
      return false;
    }
    records = chunk.records;
  } else {
    if (!codec->Decompress(chunk.compression, chunk.records, chunk.uncompressed_size, buffer,
                           error)) {
      return false;
    }
    records = buffer->view();
  }
  if (chunk.uncompressed_crc != 0) {
    const uint32_t crc = Crc32(records);
    if (crc != chunk.uncompressed_crc) {
      *error = "uncompressed CRC mismatch (expected " + Hex32(chunk.uncompressed_crc) + ", found " +
               Hex32(crc) + ")";
      return false;
    }
  }
  std::string record_error;
  for (uint64_t pos = 0;;) {
    const FrameResult framed = FrameRecord(records, pos, &record, &record_error);
    if (framed == FrameResult::kEnd) break;
    bool parsed = true;
    if (framed == FrameResult::kTruncated) {
      parsed = false;
    } else if (record.opcode == static_cast<uint8_t>(Opcode::kMessage)) {
      LocatedMessage located;
      located.offset = pos;
      parsed = internal::ParseMessage(record.body, &located.message, &record_error);
      if (parsed) messages->push_back(located);
    } else if (record.opcode == static_cast<uint8_t>(Opcode::kSchema)) {
      Schema schema;
      parsed = internal::ParseSchema(record.body, &schema, &record_error);
      if (parsed && schema.id != 0) found_schemas->emplace(schema.id, std::move(schema));
    } else if (record.opcode == static_cast<uint8_t>(Opcode::kChannel)) {
      Channel channel;
      parsed = internal::ParseChannel(record.body, &channel, &record_error);
      if (parsed) found_channels->emplace(channel.id, std::move(channel));
    }
    if (!parsed) {
      *error = "record at byte " + Str(pos) + " of the uncompressed records: " + record_error;
      messages->clear();
      return false;
    }
    pos += record.size();
  }
  return true;
}

bool McapReader::Impl::LoadChunk(ChunkInfo& chunk, ByteBuffer* buffer,
                                 std::vector<LocatedMessage>* messages) {
  if (chunk.status == ChunkStatus::kDamaged) return false;
  std::string error;
  if (!DecodeChunk(chunk, &decompressor, buffer, messages, &schemas, &channels, &error)) {
    chunk.status = ChunkStatus::kDamaged;
    damage.push_back({chunk.offset, "chunk at offset " + Str(chunk.offset) + ": " + error});
    return false;
  }
  chunk.status = ChunkStatus::kOk;
  chunk.message_count = messages->size();
  return true;
}

bool McapReader::Impl::MessageAt(uint64_t offset, MessageRecordView* message) const {
  RecordView record;
  std::string error;
  return FrameRecord(bytes, offset, &record, &error) == FrameResult::kOk &&
         record.opcode == static_cast<uint8_t>(Opcode::kMessage) &&
         internal::ParseMessage(record.body, message, &error);
}

namespace {

class MessageFilter {
 public:
  explicit MessageFilter(const ReadOptions& options)
      : start_(options.start_time), end_(options.end_time) {
    if (!options.channel_ids.empty()) {
      wanted_.assign(65536, false);
      for (const uint16_t id : options.channel_ids) wanted_[id] = true;
    }
  }
  bool Pass(const MessageRecordView& m) const {
    return m.log_time >= start_ && m.log_time <= end_ && (wanted_.empty() || wanted_[m.channel_id]);
  }
  // Whether a chunk spanning [first, last] can hold wanted messages.
  bool Overlaps(uint64_t first, uint64_t last) const { return last >= start_ && first <= end_; }

 private:
  uint64_t start_;
  uint64_t end_;
  std::vector<bool> wanted_;
};

MessageView ToView(const MessageRecordView& m) {
  return MessageView{m.channel_id, m.sequence, m.log_time, m.publish_time, m.data};
}

}  // namespace

void McapReader::Impl::ForEachInFileOrder(const std::function<bool(const MessageView&)>& fn,
                                          const ReadOptions& options) {
  const MessageFilter filter(options);
  size_t next_loose = 0;
  const auto deliver_loose_before = [&](uint64_t limit) {
    for (; next_loose < loose_messages.size() && loose_messages[next_loose] < limit; ++next_loose) {
      MessageRecordView m;
      if (MessageAt(loose_messages[next_loose], &m) && filter.Pass(m) && !fn(ToView(m))) {
        return false;
      }
    }
    return true;
  };
  for (ChunkInfo& chunk : chunks) {
    if (!deliver_loose_before(chunk.offset)) return;
    if (!filter.Overlaps(chunk.message_start_time, chunk.message_end_time)) continue;
    if (!LoadChunk(chunk, &scratch, &scratch_messages)) continue;
    for (const LocatedMessage& located : scratch_messages) {
      if (filter.Pass(located.message) && !fn(ToView(located.message))) return;
    }
  }
  deliver_loose_before(std::numeric_limits<uint64_t>::max());
}

void McapReader::Impl::ForEachInLogTimeOrder(const std::function<bool(const MessageView&)>& fn,
                                             const ReadOptions& options) {
  const MessageFilter filter(options);
  struct Source {
    uint64_t start_time;
    uint64_t offset;
    ChunkInfo* chunk;  // nullptr for a message outside chunks.
  };
  std::vector<Source> sources;
  for (ChunkInfo& chunk : chunks) {
    if (chunk.status != ChunkStatus::kDamaged &&
        filter.Overlaps(chunk.message_start_time, chunk.message_end_time)) {
      sources.push_back({chunk.message_start_time, chunk.offset, &chunk});
    }
  }
  for (const uint64_t offset : loose_messages) {
    MessageRecordView m;
    if (MessageAt(offset, &m) && filter.Pass(m)) sources.push_back({m.log_time, offset, nullptr});
  }
  std::sort(sources.begin(), sources.end(), [](const Source& a, const Source& b) {
    return a.start_time != b.start_time ? a.start_time < b.start_time : a.offset < b.offset;
  });

  // A cursor per loaded source; the heap yields the earliest next message.
  // A source is loaded once the heap's earliest message is not before the
  // source's start time, so only chunks overlapping in time are in memory.
  struct Cursor {
    uint64_t source_offset = 0;
    ByteBuffer buffer;
    std::vector<LocatedMessage> messages;
    size_t next = 0;
    const LocatedMessage& current() const { return messages[next]; }
  };
  const auto later = [](const std::unique_ptr<Cursor>& a, const std::unique_ptr<Cursor>& b) {
    const LocatedMessage& x = a->current();
    const LocatedMessage& y = b->current();
    if (x.message.log_time != y.message.log_time) return x.message.log_time > y.message.log_time;
    if (a->source_offset != b->source_offset) return a->source_offset > b->source_offset;
    return x.offset > y.offset;
  };
  std::vector<std::unique_ptr<Cursor>> heap;
  size_t next_source = 0;
  while (true) {
    while (next_source < sources.size() &&
           (heap.empty() ||
            sources[next_source].start_time <= heap.front()->current().message.log_time)) {
      const Source& source = sources[next_source++];
      auto cursor = std::make_unique<Cursor>();
      cursor->source_offset = source.offset;
      if (source.chunk != nullptr) {
        if (!LoadChunk(*source.chunk, &cursor->buffer, &cursor->messages)) continue;
        std::erase_if(cursor->messages,
                      [&](const LocatedMessage& l) { return !filter.Pass(l.message); });
        std::stable_sort(cursor->messages.begin(), cursor->messages.end(),
                         [](const LocatedMessage& a, const LocatedMessage& b) {
                           return a.message.log_time < b.message.log_time;
                         });
      } else {
        LocatedMessage located;
        located.offset = source.offset;
        if (!MessageAt(source.offset, &located.message)) continue;
        cursor->messages.push_back(located);
      }
      if (cursor->messages.empty()) continue;
      heap.push_back(std::move(cursor));
      std::push_heap(heap.begin(), heap.end(), later);
    }
    if (heap.empty()) return;
    std::pop_heap(heap.begin(), heap.end(), later);
    Cursor& cursor = *heap.back();
    if (!fn(ToView(cursor.current().message))) return;
    if (++cursor.next == cursor.messages.size()) {
      heap.pop_back();
    } else {
      std::push_heap(heap.begin(), heap.end(), later);
    }
  }
}

bool McapReader::Impl::CheckAttachment(const AttachmentInfo& info, std::span<const std::byte>* data,
                                       std::string* error) const {
  RecordView record;
  internal::AttachmentView view;
  if (FrameRecord(bytes, info.offset, &record, error) != FrameResult::kOk) return false;
  if (record.opcode != static_cast<uint8_t>(Opcode::kAttachment)) {
    *error = "expected an Attachment record, found " + OpcodeName(record.opcode);
    return false;
  }
  if (!internal::ParseAttachment(record.body, &view, error)) return false;
  if (view.crc != 0) {
    const uint32_t crc = Crc32(record.body.first(static_cast<size_t>(view.crc_covered)));
    if (crc != view.crc) {
      *error = "CRC mismatch (expected " + Hex32(view.crc) + ", found " + Hex32(crc) + ")";
      return false;
    }
  }
  *data = view.data;
  return true;
}

// --- verification ------------------------------------------------------------

VerifyReport McapReader::Impl::Verify() {
  VerifyReport report;
  std::vector<Damage>& found = report.damage;
  found = summary_damage;
  ScanResult s = Scan();
  found.insert(found.end(), s.damage.begin(), s.damage.end());

  for (const auto& [offset, opcode] : s.odd_records) {
    // 0x80-0xFF are application extensions and fine; anything else out of place
    // in the data section of a file written by rover_log means corruption.
    if (opcode < 0x80) {
      found.push_back({offset, OpcodeName(opcode) + " record at offset " + Str(offset) +
                                   " does not belong in the data section here (skipped)"});
    }
  }
  if (s.reached_footer) {
    found.push_back({footer_offset, "no Data End record before the Footer"});
  }
  if (s.data_end_offset && s.data_section_crc != 0) {
    const uint64_t end = *s.data_end_offset;
    const uint32_t crc = Crc32(bytes.first(static_cast<size_t>(end)));
    if (crc != s.data_section_crc) {
      found.push_back({end, "data section CRC mismatch over bytes [0, " + Str(end) +
                                ") (expected " + Hex32(s.data_section_crc) + ", found " +
                                Hex32(crc) + ")"});
    }
  }
  AddTailDamage(s, &found);

  // Decode every chunk: CRC, records, header times, message indexes.
  internal::ChunkDecompressor decompressor_for_verify;
  ByteBuffer buffer;
  std::vector<LocatedMessage> messages;
  std::map<uint16_t, uint64_t> counts;
  uint64_t first_time = std::numeric_limits<uint64_t>::max();
  uint64_t last_time = 0;
  uint64_t total = 0;
  const auto count_message = [&](const MessageRecordView& m, uint64_t offset,
                                 const std::string& where) {
    ++counts[m.channel_id];
    ++total;
    first_time = std::min(first_time, m.log_time);
    last_time = std::max(last_time, m.log_time);
    if (!s.channels.contains(m.channel_id)) {
      found.push_back({offset, where + ": message on channel " + Str(m.channel_id) +
                                   ", which has no earlier Channel record"});
    }
  };
  for (const ChunkInfo& chunk : s.chunks) {
    const std::string where = "chunk at offset " + Str(chunk.offset);
    std::string error;
    if (!DecodeChunk(chunk, &decompressor_for_verify, &buffer, &messages, &s.schemas, &s.channels,
                     &error)) {
      ++report.damaged_chunk_count;
      found.push_back({chunk.offset, where + ": " + error});
      continue;
    }
    std::map<uint64_t, const MessageRecordView*> by_offset;
    std::map<uint16_t, uint64_t> chunk_counts;
    uint64_t lo = std::numeric_limits<uint64_t>::max();
    uint64_t hi = 0;
    for (const LocatedMessage& l : messages) {
      count_message(l.message, chunk.offset, where);
      by_offset.emplace(l.offset, &l.message);
      ++chunk_counts[l.message.channel_id];
      lo = std::min(lo, l.message.log_time);
      hi = std::max(hi, l.message.log_time);
    }
    if (!messages.empty() && (lo != chunk.message_start_time || hi != chunk.message_end_time)) {
      found.push_back({chunk.offset, where + ": header says messages span [" +
                                         Str(chunk.message_start_time) + ", " +
                                         Str(chunk.message_end_time) + "], they span [" + Str(lo) +
                                         ", " + Str(hi) + "]"});
    }
    if (chunk.message_index_offsets.empty()) continue;  // Message indexes are optional.
    for (const auto& [channel_id, n] : chunk_counts) {
      if (!chunk.message_index_offsets.contains(channel_id)) {
        found.push_back({chunk.offset, where + ": no Message Index record for channel " +
                                           Str(channel_id) + " (" + Str(n) + " messages)"});
      }
    }
    for (const auto& [channel_id, offset] : chunk.message_index_offsets) {
      RecordView record;
      MessageIndexView index;
      // The scan framed and parsed this record already; a failure here would
      // only leave `index` empty, which the count check below reports.
      (void)FrameRecord(bytes, offset, &record, &error);
      (void)internal::ParseMessageIndex(record.body, &index, &error);
      const auto it = chunk_counts.find(channel_id);
      const uint64_t expected = it == chunk_counts.end() ? 0 : it->second;
      if (index.count() != expected) {
        found.push_back({offset, "Message Index at offset " + Str(offset) + " for channel " +
                                     Str(channel_id) + " of " + where + " lists " +
                                     Str(index.count()) + " messages, the chunk holds " +
                                     Str(expected)});
      }
      for (size_t i = 0; i < index.count(); ++i) {
        const auto m = by_offset.find(index.offset(i));
        if (m == by_offset.end() || m->second->channel_id != channel_id ||
            m->second->log_time != index.log_time(i)) {
          found.push_back({offset, "Message Index at offset " + Str(offset) + " entry " + Str(i) +
                                       " (log_time " + Str(index.log_time(i)) + ", offset " +
                                       Str(index.offset(i)) +
                                       ") does not match a message of channel " + Str(channel_id) +
                                       " in " + where});
          break;
        }
      }
    }
  }
  for (const uint64_t offset : s.loose_messages) {
    MessageRecordView m;
    if (MessageAt(offset, &m)) count_message(m, offset, "message at offset " + Str(offset));
  }
  for (const auto& [id, channel] : s.channels) {
    if (channel.schema_id != 0 && !s.schemas.contains(channel.schema_id)) {
      const auto at = s.channel_offsets.find(id);
      found.push_back({at == s.channel_offsets.end() ? 0 : at->second,
                       "Channel " + Str(id) + " ('" + channel.topic + "') refers to schema " +
                           Str(channel.schema_id) + ", which has no Schema record"});
    }
  }
  for (const AttachmentInfo& info : s.attachments) {
    std::span<const std::byte> data;
    std::string error;
    if (!CheckAttachment(info, &data, &error)) {
      found.push_back({info.offset, "attachment '" + info.name + "' at offset " + Str(info.offset) +
                                        ": " + error});
    }
  }

  // The summary must agree with what the data section holds.
  const size_t before_summary_checks = found.size();
  if (summary.ok) {
    const uint64_t at = footer.summary_start;
    std::map<uint64_t, const ChunkInfo*> scanned;
    for (const ChunkInfo& chunk : s.chunks) scanned.emplace(chunk.offset, &chunk);
    for (const ChunkInfo& indexed : summary.chunks) {
      const auto it = scanned.find(indexed.offset);
      if (it == scanned.end()) {
        found.push_back({indexed.offset, "summary: Chunk Index points at offset " +
                                             Str(indexed.offset) +
                                             ", where the data section scan found no chunk"});
        continue;
      }
      const ChunkInfo& chunk = *it->second;
      if (indexed.message_index_offsets != chunk.message_index_offsets ||
          indexed.message_index_length != chunk.message_index_length) {
        found.push_back(
            {indexed.offset, "summary: Chunk Index for offset " + Str(indexed.offset) + " lists " +
                                 Str(indexed.message_index_offsets.size()) +
                                 " message indexes in " + Str(indexed.message_index_length) +
                                 " bytes; the file has " + Str(chunk.message_index_offsets.size()) +
                                 " in " + Str(chunk.message_index_length) + " bytes"});
      }
      scanned.erase(it);
    }
    for (const auto& [offset, chunk] : scanned) {
      found.push_back({offset, "summary: chunk at offset " + Str(offset) + " has no Chunk Index"});
    }
    for (const auto& [id, schema] : s.schemas) {
      const auto it = summary.schemas.find(id);
      if (it == summary.schemas.end() || !(it->second == schema)) {
        found.push_back({at, "summary: Schema " + Str(id) + " ('" + schema.name +
                                 "') is missing or differs from the data section's"});
      }
    }
    for (const auto& [id, channel] : s.channels) {
      const auto it = summary.channels.find(id);
      if (it == summary.channels.end() || !(it->second == channel)) {
        found.push_back({at, "summary: Channel " + Str(id) + " ('" + channel.topic +
                                 "') is missing or differs from the data section's"});
      }
    }
    if (summary.statistics) {
      const Statistics& st = *summary.statistics;
      const auto check = [&](const char* field, uint64_t stated, uint64_t actual) {
        if (stated != actual) {
          found.push_back({at, std::string("summary: Statistics ") + field + " is " + Str(stated) +
                                   ", the file has " + Str(actual)});
        }
      };
      check("schema_count", st.schema_count, s.schemas.size());
      check("channel_count", st.channel_count, s.channels.size());
      check("attachment_count", st.attachment_count, s.attachments.size());
      check("metadata_count", st.metadata_count, s.metadata.size());
      check("chunk_count", st.chunk_count, s.chunks.size());
      if (report.damaged_chunk_count == 0) {  // Otherwise the true counts are unknown.
        check("message_count", st.message_count, total);
        check("message_start_time", st.message_start_time, total == 0 ? 0 : first_time);
        check("message_end_time", st.message_end_time, last_time);
        if (!st.channel_message_counts.empty()) {
          for (const auto& [id, n] : counts) {
            const auto it = st.channel_message_counts.find(id);
            check(("channel_message_counts[" + Str(id) + "]").c_str(),
                  it == st.channel_message_counts.end() ? 0 : it->second, n);
          }
          for (const auto& [id, n] : st.channel_message_counts) {
            if (!counts.contains(id)) {
              check(("channel_message_counts[" + Str(id) + "]").c_str(), n, 0);
            }
          }
        }
      }
    }
  }

  report.summary_ok = summary.ok && found.size() == before_summary_checks;
  report.truncated = !footer_ok;
  report.message_count = total;
  report.chunk_count = s.chunks.size();
  report.schema_count = s.schemas.size();
  report.channel_count = s.channels.size();
  report.metadata_count = s.metadata.size();
  report.attachment_count = s.attachments.size();
  report.ok = found.empty() && footer_ok;
  return report;
}

// --- public interface --------------------------------------------------------

McapReader::McapReader(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
McapReader::McapReader(McapReader&&) noexcept = default;
McapReader& McapReader::operator=(McapReader&&) noexcept = default;
McapReader::~McapReader() = default;

McapReader McapReader::Open(const std::string& path, const OpenOptions& options) {
  auto impl = std::make_unique<Impl>();
  impl->name = path;
  impl->storage = Storage::MapFile(path);
  impl->bytes = impl->storage->bytes();
  impl->Init(options);
  return McapReader(std::move(impl));
}

McapReader McapReader::Open(std::span<const std::byte> bytes, const OpenOptions& options) {
  auto impl = std::make_unique<Impl>();
  impl->name = "<memory>";
  impl->storage = Storage::Copy(bytes);
  impl->bytes = impl->storage->bytes();
  impl->Init(options);
  return McapReader(std::move(impl));
}

const Header& McapReader::header() const { return impl_->header; }
const std::map<uint16_t, Schema>& McapReader::schemas() const { return impl_->schemas; }
const std::map<uint16_t, Channel>& McapReader::channels() const { return impl_->channels; }
const std::vector<Metadata>& McapReader::metadata() const { return impl_->metadata; }
const std::vector<AttachmentInfo>& McapReader::attachments() const { return impl_->attachments; }
const std::optional<Statistics>& McapReader::statistics() const { return impl_->statistics; }
const std::vector<ChunkInfo>& McapReader::chunks() const { return impl_->chunks; }
bool McapReader::summary_ok() const { return impl_->use_summary; }
bool McapReader::truncated() const { return !impl_->footer_ok; }
const std::vector<Damage>& McapReader::damage() const { return impl_->damage; }
uint64_t McapReader::file_size() const { return impl_->bytes.size(); }

void McapReader::ForEachMessage(const std::function<bool(const MessageView&)>& fn,
                                const ReadOptions& options) {
  if (options.order == ReadOptions::Order::kLogTime) {
    impl_->ForEachInLogTimeOrder(fn, options);
  } else {
    impl_->ForEachInFileOrder(fn, options);
  }
}

std::optional<std::vector<std::byte>> McapReader::ReadAttachment(const AttachmentInfo& attachment) {
  std::span<const std::byte> data;
  std::string error;
  if (!impl_->CheckAttachment(attachment, &data, &error)) {
    impl_->damage.push_back({attachment.offset, "attachment '" + attachment.name + "' at offset " +
                                                    Str(attachment.offset) + ": " + error});
    return std::nullopt;
  }
  return std::vector<std::byte>(data.begin(), data.end());
}

VerifyReport McapReader::Verify() { return impl_->Verify(); }

namespace {

template <typename Source>
VerifyReport VerifySource(const Source& source) {
  try {
    return McapReader::Open(source).Verify();
  } catch (const McapError& e) {
    VerifyReport report;
    report.truncated = true;
    report.damage.push_back({0, e.what()});
    return report;
  }
}

}  // namespace

VerifyReport Verify(const std::string& path) { return VerifySource(path); }
VerifyReport Verify(std::span<const std::byte> bytes) { return VerifySource(bytes); }

}  // namespace rover::log
