#include "core/log/mcap/mcap_writer.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <system_error>
#include <utility>

#include "core/log/mcap/crc32.h"

namespace rover::log {
namespace {

using internal::Opcode;

std::string ErrnoText(int err) { return std::error_code(err, std::generic_category()).message(); }

// Smallest unused id at or after `next`, wrapping past 65535 to 1.
template <typename Map>
uint16_t FreeId(const Map& used, uint16_t next, const char* what) {
  uint16_t id = next == 0 ? 1 : next;
  for (uint32_t tries = 0; tries < 65535; ++tries) {
    if (!used.contains(id)) return id;
    id = id == 65535 ? 1 : static_cast<uint16_t>(id + 1);
  }
  throw McapError(std::string("all 65535 ") + what + " ids are in use");
}

}  // namespace

McapWriter::McapWriter(McapWriterOptions options)
    : options_(std::move(options)), compressor_(options_.compression, options_.zstd_level) {}

McapWriter::~McapWriter() {
  try {
    Close();
  } catch (...) {
    // Destructors must not throw; the file keeps every chunk written so far.
    CloseFd();
  }
}

void McapWriter::Open(const std::string& path) {
  if (fd_ >= 0) {
    throw McapError("cannot open MCAP file " + path + ": this writer still has " + path_ + " open");
  }
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw McapError("cannot create MCAP file " + path + ": " + ErrnoText(errno));

  fd_ = fd;
  path_ = path;
  failed_ = false;
  offset_ = 0;
  data_crc_ = 0;
  schemas_.clear();
  channels_.clear();
  next_schema_id_ = 1;
  next_channel_id_ = 1;
  chunk_records_.clear();
  chunk_channels_.clear();
  chunk_messages_ = 0;
  chunk_indexes_.clear();
  metadata_indexes_.clear();
  attachment_indexes_.clear();
  message_start_time_ = 0;
  message_end_time_ = 0;
  stats_ = {};
  // Reserve the usual chunk size up front so steady-state writing does not
  // reallocate; a very large limit is left to grow on demand.
  chunk_records_.reserve(static_cast<size_t>(
      std::min<uint64_t>(options_.chunk_size_bytes + (64U << 10), uint64_t{16} << 20)));

  out_.clear();
  internal::PutBytes(out_, internal::kMagic);
  internal::AppendHeader(out_, Header{options_.profile, options_.library});
  try {
    WriteOut(out_, true);
  } catch (...) {
    CloseFd();
    throw;
  }
}

void McapWriter::CheckWritable(const char* what) const {
  if (fd_ < 0) throw McapError(std::string(what) + ": no MCAP file is open");
  if (failed_) {
    throw McapError(std::string(what) + ": an earlier write to " + path_ +
                    " failed; the file ends at its last complete record");
  }
}

uint16_t McapWriter::AddSchema(std::string_view name, std::string_view encoding,
                               std::span<const std::byte> data) {
  CheckWritable("AddSchema");
  for (const auto& [id, schema] : schemas_) {
    if (schema.name == name && schema.encoding == encoding &&
        std::ranges::equal(schema.data, data)) {
      return id;
    }
  }
  const uint16_t id = FreeId(schemas_, next_schema_id_, "schema");
  AddSchemaRecord(Schema{id, std::string(name), std::string(encoding), {data.begin(), data.end()}});
  next_schema_id_ = static_cast<uint16_t>(id + 1);
  return id;
}

void McapWriter::AddSchemaWithId(uint16_t id, std::string_view name, std::string_view encoding,
                                 std::span<const std::byte> data) {
  CheckWritable("AddSchemaWithId");
  if (id == 0) throw McapError("AddSchemaWithId: schema id 0 is reserved for 'no schema'");
  if (schemas_.contains(id)) {
    throw McapError("AddSchemaWithId: schema id " + std::to_string(id) + " is already used");
  }
  AddSchemaRecord(Schema{id, std::string(name), std::string(encoding), {data.begin(), data.end()}});
}

void McapWriter::AddSchemaRecord(Schema schema) {
  out_.clear();
  internal::AppendSchema(out_, schema);
  WriteOut(out_, true);
  const uint16_t id = schema.id;
  schemas_.emplace(id, std::move(schema));
  ++stats_.schemas;
}

uint16_t McapWriter::AddChannel(uint16_t schema_id, std::string_view topic,
                                std::string_view message_encoding,
                                const std::map<std::string, std::string>& metadata) {
  CheckWritable("AddChannel");
  for (const auto& [id, state] : channels_) {
    const Channel& c = state.channel;
    if (c.schema_id == schema_id && c.topic == topic && c.message_encoding == message_encoding &&
        c.metadata == metadata) {
      return id;
    }
  }
  const uint16_t id = FreeId(channels_, next_channel_id_, "channel");
  AddChannelRecord(
      Channel{id, schema_id, std::string(topic), std::string(message_encoding), metadata});
  next_channel_id_ = static_cast<uint16_t>(id + 1);
  return id;
}

void McapWriter::AddChannelWithId(uint16_t id, uint16_t schema_id, std::string_view topic,
                                  std::string_view message_encoding,
                                  const std::map<std::string, std::string>& metadata) {
  CheckWritable("AddChannelWithId");
  if (channels_.contains(id)) {
    throw McapError("AddChannelWithId: channel id " + std::to_string(id) + " is already used");
  }
  AddChannelRecord(
      Channel{id, schema_id, std::string(topic), std::string(message_encoding), metadata});
}

void McapWriter::AddChannelRecord(Channel channel) {
  if (channel.schema_id != 0 && !schemas_.contains(channel.schema_id)) {
    throw McapError("channel '" + channel.topic + "': unknown schema id " +
                    std::to_string(channel.schema_id) + " (add the schema first, or use 0)");
  }
  out_.clear();
  internal::AppendChannel(out_, channel);
  WriteOut(out_, true);
  const uint16_t id = channel.id;
  channels_.emplace(id, ChannelState{std::move(channel), 0, {}});
  chunk_channels_.reserve(channels_.size());
  ++stats_.channels;
}

void McapWriter::WriteMessage(uint16_t channel_id, uint32_t sequence, uint64_t log_time_ns,
                              uint64_t publish_time_ns, std::span<const std::byte> data) {
  CheckWritable("WriteMessage");
  const auto it = channels_.find(channel_id);
  if (it == channels_.end()) {
    throw McapError("WriteMessage: unknown channel id " + std::to_string(channel_id) +
                    " (add it with AddChannel first)");
  }
  ChannelState& channel = it->second;
  if (channel.chunk_index.empty()) chunk_channels_.push_back(channel_id);
  channel.chunk_index.push_back({log_time_ns, chunk_records_.size()});
  internal::AppendMessage(chunk_records_, channel_id, sequence, log_time_ns, publish_time_ns, data);
  ++channel.message_count;

  if (chunk_messages_ == 0) {
    chunk_start_time_ = chunk_end_time_ = log_time_ns;
  } else {
    chunk_start_time_ = std::min(chunk_start_time_, log_time_ns);
    chunk_end_time_ = std::max(chunk_end_time_, log_time_ns);
  }
  if (stats_.messages == 0) {
    message_start_time_ = message_end_time_ = log_time_ns;
  } else {
    message_start_time_ = std::min(message_start_time_, log_time_ns);
    message_end_time_ = std::max(message_end_time_, log_time_ns);
  }
  ++chunk_messages_;
  ++stats_.messages;

  const bool full = chunk_records_.size() >= options_.chunk_size_bytes;
  const bool old =
      options_.max_chunk_duration_ns > 0 &&
      chunk_end_time_ - chunk_start_time_ >= static_cast<uint64_t>(options_.max_chunk_duration_ns);
  if (full || old) FlushChunk();
}

void McapWriter::WriteMetadata(std::string_view name,
                               const std::map<std::string, std::string>& metadata) {
  CheckWritable("WriteMetadata");
  out_.clear();
  internal::AppendMetadata(out_, Metadata{std::string(name), metadata});
  const internal::MetadataIndexRecord index{offset_, out_.size(), std::string(name)};
  WriteOut(out_, true);
  metadata_indexes_.push_back(index);
  ++stats_.metadata;
}

void McapWriter::WriteAttachment(std::string_view name, std::string_view media_type,
                                 uint64_t log_time_ns, uint64_t create_time_ns,
                                 std::span<const std::byte> data) {
  CheckWritable("WriteAttachment");
  out_.clear();
  internal::AppendAttachment(out_, log_time_ns, create_time_ns, name, media_type, data);
  const AttachmentInfo info{offset_,        out_.size(),       log_time_ns,
                            create_time_ns, std::string(name), std::string(media_type),
                            data.size()};
  WriteOut(out_, true);
  attachment_indexes_.push_back(info);
  ++stats_.attachments;
}

void McapWriter::FlushChunk() {
  if (chunk_messages_ == 0) return;
  CheckWritable("FlushChunk");
  const std::string_view compression = CompressionName(options_.compression);
  const uint32_t crc = Crc32(chunk_records_);

  // Compress straight behind the chunk header in the staging buffer, so the
  // chunk and its message indexes leave in one write(2): a crash can then cut
  // the file only between whole chunks or inside the last one.
  const size_t prefix = internal::kRecordPrefixSize + 8 + 8 + 8 + 4 + 4 + compression.size() + 8;
  const size_t bound = compressor_.Bound(chunk_records_.size());
  out_.resize(prefix + bound);
  const size_t compressed =
      compressor_.Compress(chunk_records_, std::span(out_).subspan(prefix, bound));
  out_.resize(prefix + compressed);
  std::byte* p = out_.data();
  p[0] = static_cast<std::byte>(Opcode::kChunk);
  internal::StoreLe<uint64_t>(p + 1, out_.size() - internal::kRecordPrefixSize);
  internal::StoreLe<uint64_t>(p + 9, chunk_start_time_);
  internal::StoreLe<uint64_t>(p + 17, chunk_end_time_);
  internal::StoreLe<uint64_t>(p + 25, chunk_records_.size());
  internal::StoreLe<uint32_t>(p + 33, crc);
  internal::StoreLe<uint32_t>(p + 37, static_cast<uint32_t>(compression.size()));
  std::memcpy(p + 41, compression.data(), compression.size());
  internal::StoreLe<uint64_t>(p + 41 + compression.size(), compressed);

  internal::ChunkIndexRecord index;
  index.message_start_time = chunk_start_time_;
  index.message_end_time = chunk_end_time_;
  index.chunk_start_offset = offset_;
  index.chunk_length = out_.size();
  index.compression = std::string(compression);
  index.compressed_size = compressed;
  index.uncompressed_size = chunk_records_.size();

  std::sort(chunk_channels_.begin(), chunk_channels_.end());
  for (const uint16_t channel_id : chunk_channels_) {
    std::vector<IndexEntry>& entries = channels_.at(channel_id).chunk_index;
    const auto by_time = [](const IndexEntry& a, const IndexEntry& b) {
      return a.log_time != b.log_time ? a.log_time < b.log_time : a.offset < b.offset;
    };
    // Readers binary-search message indexes by time; out-of-order stamps are rare.
    if (!std::is_sorted(entries.begin(), entries.end(), by_time)) {
      std::sort(entries.begin(), entries.end(), by_time);
    }
    index.message_index_offsets.emplace(channel_id, offset_ + out_.size());
    const size_t r = internal::BeginRecord(out_, Opcode::kMessageIndex);
    internal::PutU16(out_, channel_id);
    internal::PutU32(out_,
                     static_cast<uint32_t>(entries.size() * internal::kMessageIndexEntrySize));
    for (const IndexEntry& e : entries) {
      internal::PutU64(out_, e.log_time);
      internal::PutU64(out_, e.offset);
    }
    internal::EndRecord(out_, r);
    entries.clear();
  }
  index.message_index_length = out_.size() - index.chunk_length;

  WriteOut(out_, true);
  if (options_.sync_each_chunk && ::fdatasync(fd_) != 0) {
    failed_ = true;
    throw McapError("fdatasync of " + path_ + " failed: " + ErrnoText(errno));
  }
  chunk_indexes_.push_back(std::move(index));
  ++stats_.chunks;
  stats_.uncompressed_bytes += chunk_records_.size();
  stats_.compressed_bytes += compressed;
  chunk_records_.clear();
  chunk_channels_.clear();
  chunk_messages_ = 0;
}

void McapWriter::Close() {
  if (fd_ < 0) return;
  if (failed_) {
    // The summary would describe data that is not there; leave the file as a
    // truncated log, which the reader handles.
    CloseFd();
    return;
  }
  try {
    FlushChunk();
    out_.clear();
    internal::AppendDataEnd(out_, data_crc_);
    const uint64_t summary_start = offset_ + out_.size();

    std::vector<internal::SummaryOffsetRecord> groups;
    const auto group = [&](Opcode opcode, const auto& append) {
      const size_t start = out_.size();
      append();
      if (out_.size() > start) {
        groups.push_back({static_cast<uint8_t>(opcode), offset_ + start, out_.size() - start});
      }
    };
    group(Opcode::kSchema, [&] {
      for (const auto& [id, schema] : schemas_) internal::AppendSchema(out_, schema);
    });
    group(Opcode::kChannel, [&] {
      for (const auto& [id, state] : channels_) internal::AppendChannel(out_, state.channel);
    });
    group(Opcode::kStatistics, [&] {
      Statistics s;
      s.message_count = stats_.messages;
      s.schema_count = static_cast<uint16_t>(schemas_.size());
      s.channel_count = static_cast<uint32_t>(channels_.size());
      s.attachment_count = static_cast<uint32_t>(attachment_indexes_.size());
      s.metadata_count = static_cast<uint32_t>(metadata_indexes_.size());
      s.chunk_count = static_cast<uint32_t>(chunk_indexes_.size());
      s.message_start_time = message_start_time_;
      s.message_end_time = message_end_time_;
      // Every channel is listed, with 0 for silent ones, so readers can tell
      // "no messages" from "not counted".
      for (const auto& [id, state] : channels_) s.channel_message_counts[id] = state.message_count;
      internal::AppendStatistics(out_, s);
    });
    group(Opcode::kChunkIndex, [&] {
      for (const auto& index : chunk_indexes_) internal::AppendChunkIndex(out_, index);
    });
    group(Opcode::kAttachmentIndex, [&] {
      for (const auto& info : attachment_indexes_) internal::AppendAttachmentIndex(out_, info);
    });
    group(Opcode::kMetadataIndex, [&] {
      for (const auto& index : metadata_indexes_) internal::AppendMetadataIndex(out_, index);
    });
    const uint64_t summary_offset_start = offset_ + out_.size();
    for (const auto& g : groups) internal::AppendSummaryOffset(out_, g);

    // The footer is written by hand: its CRC covers the summary, the summary
    // offsets and the footer's own opcode, length and two offsets, so the
    // length must be in place before the CRC is computed.
    internal::PutU8(out_, static_cast<uint8_t>(Opcode::kFooter));
    internal::PutU64(out_, internal::kFooterBodySize);
    internal::PutU64(out_, summary_start);
    internal::PutU64(out_, summary_offset_start);
    const size_t summary_index = static_cast<size_t>(summary_start - offset_);
    internal::PutU32(out_, Crc32(std::span(out_).subspan(summary_index)));
    internal::PutBytes(out_, internal::kMagic);
    WriteOut(out_, false);

    if (::fdatasync(fd_) != 0) {
      throw McapError("fdatasync of " + path_ + " failed: " + ErrnoText(errno));
    }
    const int fd = fd_;
    fd_ = -1;
    if (::close(fd) != 0) throw McapError("close of " + path_ + " failed: " + ErrnoText(errno));
  } catch (...) {
    CloseFd();
    throw;
  }
}

void McapWriter::WriteOut(std::span<const std::byte> bytes, bool data_section) {
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd_, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      failed_ = true;
      const std::string why = n < 0 ? ErrnoText(errno) : "no bytes written";
      throw McapError("write of " + std::to_string(bytes.size()) + " bytes to " + path_ +
                      " at offset " + std::to_string(offset_ + done) + " failed: " + why);
    }
    done += static_cast<size_t>(n);
  }
  if (data_section) data_crc_ = Crc32(bytes, data_crc_);
  offset_ += bytes.size();
  stats_.bytes_written = offset_;
}

void McapWriter::CloseFd() {
  if (fd_ >= 0) {
    ::close(fd_);
    fd_ = -1;
  }
}

}  // namespace rover::log
