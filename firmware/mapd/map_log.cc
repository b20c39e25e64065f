#include "firmware/mapd/map_log.h"

#include <filesystem>
#include <span>

namespace rover::mapd {

MapLog::MapLog(const std::string& path) : path_(path) {
  const std::filesystem::path p(path);
  if (p.has_parent_path()) std::filesystem::create_directories(p.parent_path());
  writer_.Open(path);
}

MapLog::~MapLog() = default;

uint16_t MapLog::Channel(std::string_view topic, std::string_view type,
                         std::string_view definition) {
  const auto it = channels_.find(topic);
  if (it != channels_.end()) return it->second;
  const uint16_t schema = writer_.AddSchema(
      type, "ros2msg", std::as_bytes(std::span(definition.data(), definition.size())));
  const uint16_t channel = writer_.AddChannel(schema, topic, "cdr");
  channels_.emplace(std::string(topic), channel);
  return channel;
}

}  // namespace rover::mapd
