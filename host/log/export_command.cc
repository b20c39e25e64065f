#include <fstream>
#include <map>
#include <optional>
#include <string_view>

#include "core/log/mcap/mcap_reader.h"
#include "core/log/schema/dynamic_decoder.h"
#include "host/log/commands.h"

namespace rover::host {
namespace {

// Quotes a CSV cell when it holds a separator, a quote or a line break.
std::string CsvCell(const std::string& value) {
  if (value.find_first_of(",\"\n\r") == std::string::npos) return value;
  std::string quoted = "\"";
  for (const char c : value) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  return quoted + "\"";
}

}  // namespace

int RunExport(const ExportOptions& options, std::ostream& out, std::ostream& err) {
  std::optional<log::McapReader> opened;
  try {
    opened.emplace(log::McapReader::Open(options.path));
  } catch (const std::exception& e) {
    err << "rover-log export: " << e.what() << "\n";
    return 2;
  }
  log::McapReader& reader = *opened;

  const log::Channel* channel = nullptr;
  for (const auto& [id, c] : reader.channels()) {
    if (c.topic == options.topic) channel = &c;
  }
  if (channel == nullptr) {
    err << "rover-log export: no topic '" << options.topic << "' in " << options.path
        << "; topics are:";
    for (const auto& [id, c] : reader.channels()) err << " " << c.topic;
    err << "\n";
    return 2;
  }
  const auto schema_it = reader.schemas().find(channel->schema_id);
  if (channel->message_encoding != "cdr" || schema_it == reader.schemas().end() ||
      schema_it->second.encoding != "ros2msg") {
    err << "rover-log export: topic '" << options.topic
        << "' is not CDR with a ros2msg schema (message encoding '" << channel->message_encoding
        << "'); only ROS 2 messages can be exported\n";
    return 2;
  }
  const log::Schema& schema = schema_it->second;
  std::optional<log::Ros2MsgSchema> parsed;
  try {
    parsed.emplace(log::Ros2MsgSchema::Parse(
        schema.name,
        std::string_view(reinterpret_cast<const char*>(schema.data.data()), schema.data.size())));
  } catch (const log::SchemaError& e) {
    err << "rover-log export: schema " << schema.name << " in " << options.path << ": " << e.what()
        << "\n";
    return 2;
  }
  const log::DynamicDecoder decoder(*parsed);

  std::ofstream file;
  std::ostream* csv = &out;
  if (!options.output.empty() && options.output != "-") {
    file.open(options.output);
    if (!file) {
      err << "rover-log export: cannot write " << options.output << "\n";
      return 2;
    }
    csv = &file;
  }

  // Variable-length sequences give messages different leaves, so the first
  // pass collects the union of columns in order of first appearance.
  log::ReadOptions read;
  read.channel_ids = {channel->id};
  std::vector<std::string> columns;
  std::map<std::string, std::size_t, std::less<>> column_of;
  std::vector<log::FlatField> fields;
  uint64_t undecodable = 0;
  std::string error;
  reader.ForEachMessage(
      [&](const log::MessageView& m) {
        if (!decoder.Decode(m.data, &fields, &error)) {
          if (undecodable++ == 0) {
            err << "rover-log export: message at log_time " << m.log_time << " (sequence "
                << m.sequence << ") cannot be decoded: " << error << "\n";
          }
          return true;
        }
        for (const log::FlatField& f : fields) {
          if (column_of.emplace(f.path, columns.size()).second) columns.push_back(f.path);
        }
        return true;
      },
      read);

  *csv << "log_time_ns,sequence";
  for (const std::string& c : columns) *csv << "," << CsvCell(c);
  *csv << "\n";
  uint64_t rows = 0;
  std::vector<std::string> row(columns.size());
  reader.ForEachMessage(
      [&](const log::MessageView& m) {
        if (!decoder.Decode(m.data, &fields, &error)) return true;  // reported above
        std::fill(row.begin(), row.end(), std::string());
        for (const log::FlatField& f : fields)
          row[column_of.find(f.path)->second] = log::FormatValue(f);
        *csv << m.log_time << "," << m.sequence;
        for (const std::string& cell : row) *csv << "," << CsvCell(cell);
        *csv << "\n";
        ++rows;
        return true;
      },
      read);
  csv->flush();
  err << "rover-log export: " << rows << " rows of " << options.topic << " (" << schema.name << ", "
      << columns.size() << " fields)";
  if (undecodable > 0) err << "; " << undecodable << " undecodable message(s) skipped";
  err << "\n";
  if (!reader.damage().empty()) {
    err << "rover-log export: the file is damaged (" << reader.damage().size()
        << " problem(s)); rows from damaged chunks are missing, see `rover-log verify`\n";
  }
  return undecodable > 0 || !reader.damage().empty() ? 1 : 0;
}

}  // namespace rover::host
