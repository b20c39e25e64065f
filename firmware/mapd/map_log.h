#ifndef ROVER_FIRMWARE_MAPD_MAP_LOG_H_
#define ROVER_FIRMWARE_MAPD_MAP_LOG_H_

// mapd's own MCAP log (ROS 2 CDR, like roverd's flight log): finished
// submaps (rover_msgs/SubmapInfo, octomap_msgs/Octomap,
// sensor_msgs/PointCloud2) and the traversability grid
// (nav_msgs/OccupancyGrid). mapd may crash without touching roverd, so it
// keeps its own file; the board's log service lists and serves both.
// Each submap is flushed as its own chunk, so a crash loses at most the
// submap being built.

#include <cstdint>
#include <map>
#include <string>
#include <string_view>

#include "core/log/mcap/mcap_writer.h"
#include "core/log/msgs/message_traits.h"

namespace rover::mapd {

class MapLog {
 public:
  /// Creates `path` (its folder too). Throws log::McapError naming the path.
  explicit MapLog(const std::string& path);
  ~MapLog();
  MapLog(const MapLog&) = delete;
  MapLog& operator=(const MapLog&) = delete;

  /// Writes `msg` on `topic` (the channel is created on first use) and
  /// returns its serialised size in bytes.
  template <log::RosMessage T>
  std::size_t Write(std::string_view topic, int64_t stamp_ns, const T& msg) {
    const uint16_t channel =
        Channel(topic, log::MessageTraits<T>::kName, log::MessageTraits<T>::Definition());
    const std::vector<std::byte> bytes = log::SerializeMessage(msg);
    const auto t = static_cast<uint64_t>(stamp_ns);
    writer_.WriteMessage(channel, sequence_++, t, t, bytes);
    return bytes.size();
  }
  /// Ends the current chunk (on disk: survives a crash from here on).
  void Flush() { writer_.FlushChunk(); }
  /// Adds a metadata record (e.g. the run's statistics).
  void WriteMetadata(std::string_view name, const std::map<std::string, std::string>& values) {
    writer_.WriteMetadata(name, values);
  }
  /// Writes the summary and closes; idempotent.
  void Close() { writer_.Close(); }
  const std::string& path() const { return path_; }

 private:
  uint16_t Channel(std::string_view topic, std::string_view type, std::string_view definition);

  std::string path_;
  log::McapWriter writer_;
  std::map<std::string, uint16_t, std::less<>> channels_;
  uint32_t sequence_ = 0;
};

}  // namespace rover::mapd

#endif  // ROVER_FIRMWARE_MAPD_MAP_LOG_H_
