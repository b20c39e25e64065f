#include <filesystem>
#include <set>

#include "core/log/mcap/mcap_reader.h"
#include "core/log/mcap/mcap_writer.h"

namespace rover::log {

RecoverResult Recover(const std::string& in, const std::string& out,
                      const McapWriterOptions& options) {
  std::error_code ec;
  if (std::filesystem::exists(out, ec) && std::filesystem::equivalent(in, out, ec)) {
    throw McapError("Recover: output " + out + " is the input file; write to a new file");
  }
  // The linear scan also finds messages outside chunks and chunks that a
  // damaged summary would not list.
  McapReader reader = McapReader::Open(in, OpenOptions{.use_summary = false});
  McapWriterOptions writer_options = options;
  writer_options.profile = reader.header().profile;
  McapWriter writer(writer_options);
  writer.Open(out);

  RecoverResult result;
  uint64_t unknown_channel_messages = 0;
  std::set<uint16_t> written_schemas;
  std::set<uint16_t> written_channels;
  const auto write_schema = [&](uint16_t id) {
    const auto it = reader.schemas().find(id);
    if (it == reader.schemas().end() || written_schemas.contains(id)) return;
    writer.AddSchemaWithId(id, it->second.name, it->second.encoding, it->second.data);
    written_schemas.insert(id);
  };
  const auto write_channel = [&](const Channel& channel) {
    write_schema(channel.schema_id);
    // A channel whose schema record is lost keeps its messages, without schema.
    const uint16_t schema_id = written_schemas.contains(channel.schema_id) ? channel.schema_id : 0;
    writer.AddChannelWithId(channel.id, schema_id, channel.topic, channel.message_encoding,
                            channel.metadata);
    written_channels.insert(channel.id);
  };

  for (const auto& [id, schema] : reader.schemas()) write_schema(id);
  for (const auto& [id, channel] : reader.channels()) write_channel(channel);
  for (const Metadata& metadata : reader.metadata()) {
    writer.WriteMetadata(metadata.name, metadata.metadata);
  }
  for (const AttachmentInfo& info : reader.attachments()) {
    if (const auto data = reader.ReadAttachment(info)) {
      writer.WriteAttachment(info.name, info.media_type, info.log_time, info.create_time, *data);
    }
  }
  reader.ForEachMessage([&](const MessageView& m) {
    if (!written_channels.contains(m.channel_id)) {
      // Channel records inside chunks become known as the chunks are decoded.
      const auto it = reader.channels().find(m.channel_id);
      if (it == reader.channels().end()) {
        ++result.messages_dropped;
        ++unknown_channel_messages;
        return true;
      }
      write_channel(it->second);
    }
    writer.WriteMessage(m.channel_id, m.sequence, m.log_time, m.publish_time, m.data);
    ++result.messages_written;
    return true;
  });
  writer.Close();

  for (const ChunkInfo& chunk : reader.chunks()) {
    if (chunk.status == ChunkStatus::kDamaged) {
      ++result.chunks_dropped;
      result.messages_dropped += chunk.message_count;
    } else {
      ++result.chunks_recovered;
    }
  }
  result.input_truncated = reader.truncated();
  result.dropped = reader.damage();
  if (unknown_channel_messages > 0) {
    result.dropped.push_back({0, std::to_string(unknown_channel_messages) +
                                     " messages on channels without a Channel record"});
  }
  return result;
}

}  // namespace rover::log
