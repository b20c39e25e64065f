#ifndef ROVER_CORE_IPC_TOPIC_H_
#define ROVER_CORE_IPC_TOPIC_H_

// Topic names and their mapping onto iceoryx service descriptions.
//
// Code names topics like file paths, "/roverd/pose". iceoryx addresses a
// stream by the triple (service, instance, event); the mapping is:
//
//   "/roverd/pose"              -> ("roverd", "default", "pose")
//   "/roverd/camera/left/image" -> ("roverd", "camera/left", "image")
//
// i.e. the first component is the service (by convention the publishing
// process), the last one the event, and whatever lies between is the
// instance ("default" if nothing). The in-process transport uses the same
// triple, so both transports accept and reject the same names.

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace rover::ipc {

class Topic {
 public:
  /// iceoryx stores each part in a fixed 100-character string.
  static constexpr std::size_t kMaxPartChars = 100;
  /// Instance used when the name has only two components.
  static constexpr std::string_view kDefaultInstance = "default";

  /// Parses an absolute topic name: at least two non-empty components made
  /// of [A-Za-z0-9_.-], separated by single '/', no trailing '/'. Returns
  /// nullopt (and a reason in `*error` if given) for anything else, or if a
  /// part would exceed kMaxPartChars.
  static std::optional<Topic> Parse(std::string_view name, std::string* error = nullptr);

  /// The name as given to Parse, e.g. "/roverd/pose".
  const std::string& name() const { return name_; }
  /// First component, e.g. "roverd".
  const std::string& service() const { return service_; }
  /// Middle components joined with '/', or kDefaultInstance.
  const std::string& instance() const { return instance_; }
  /// Last component, e.g. "pose".
  const std::string& event() const { return event_; }

  /// "service/instance/event": identifies the stream. Two names that map to
  /// the same triple ("/a/b" and "/a/default/b") are the same topic.
  std::string Key() const { return service_ + "/" + instance_ + "/" + event_; }

  /// Same stream (same service, instance and event).
  friend bool operator==(const Topic& a, const Topic& b) {
    return a.service_ == b.service_ && a.instance_ == b.instance_ && a.event_ == b.event_;
  }

 private:
  Topic() = default;

  std::string name_;
  std::string service_;
  std::string instance_;
  std::string event_;
};

}  // namespace rover::ipc

#endif  // ROVER_CORE_IPC_TOPIC_H_
