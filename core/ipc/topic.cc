#include "core/ipc/topic.h"

#include <vector>

namespace rover::ipc {
namespace {

bool IsNameChar(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
         c == '-' || c == '.';
}

std::optional<Topic> Fail(std::string* error, std::string_view name, std::string_view reason) {
  if (error != nullptr) {
    *error = "invalid topic name '" + std::string(name) + "': " + std::string(reason);
  }
  return std::nullopt;
}

}  // namespace

std::optional<Topic> Topic::Parse(std::string_view name, std::string* error) {
  if (name.empty() || name.front() != '/') {
    return Fail(error, name, "must start with '/'");
  }
  std::vector<std::string_view> parts;
  std::size_t start = 1;
  while (true) {
    const std::size_t slash = name.find('/', start);
    const std::string_view part = name.substr(
        start, slash == std::string_view::npos ? std::string_view::npos : slash - start);
    if (part.empty()) {
      return Fail(error, name, "empty component (double or trailing '/')");
    }
    for (const char c : part) {
      if (!IsNameChar(c)) {
        return Fail(error, name, "components may only contain [A-Za-z0-9_.-]");
      }
    }
    parts.push_back(part);
    if (slash == std::string_view::npos) {
      break;
    }
    start = slash + 1;
  }
  if (parts.size() < 2) {
    return Fail(error, name, "needs at least /service/event");
  }

  Topic topic;
  topic.name_ = std::string(name);
  topic.service_ = std::string(parts.front());
  topic.event_ = std::string(parts.back());
  if (parts.size() == 2) {
    topic.instance_ = std::string(kDefaultInstance);
  } else {
    // Everything between the '/' after the service and the last '/'.
    const std::size_t instance_begin = 1 + parts.front().size() + 1;
    const std::size_t instance_end = name.rfind('/');
    topic.instance_ = std::string(name.substr(instance_begin, instance_end - instance_begin));
  }
  if (topic.service_.size() > kMaxPartChars || topic.instance_.size() > kMaxPartChars ||
      topic.event_.size() > kMaxPartChars) {
    return Fail(error, name, "service, instance and event must each be at most 100 characters");
  }
  return topic;
}

}  // namespace rover::ipc
