#include "core/log/archive/log_name.h"

namespace rover::log {
namespace {

constexpr std::string_view kSuffix = ".mcap";

bool IsNameChar(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '.' ||
         c == '_' || c == '-';
}

// The character for an error message: printable ASCII as is, others as \xNN.
std::string Show(char c) {
  const auto u = static_cast<unsigned char>(c);
  if (u >= 0x21 && u < 0x7F) return std::string("'") + c + "'";
  static constexpr char kHex[] = "0123456789abcdef";
  return std::string("byte 0x") + kHex[u >> 4] + kHex[u & 0x0F];
}

bool Fail(std::string* why, std::string text) {
  if (why != nullptr) *why = std::move(text);
  return false;
}

}  // namespace

bool IsValidLogName(std::string_view name, std::string* why) {
  if (name.empty()) return Fail(why, "expected a log file name, found an empty name");
  if (name.size() > kMaxLogNameBytes) {
    return Fail(why, "expected a log name of at most " + std::to_string(kMaxLogNameBytes) +
                         " bytes, found " + std::to_string(name.size()) + " bytes");
  }
  for (size_t i = 0; i < name.size(); ++i) {
    if (!IsNameChar(name[i])) {
      return Fail(why, "expected only letters, digits, '.', '_' and '-' in a log name, found " +
                           Show(name[i]) + " at position " + std::to_string(i));
    }
  }
  if (name.front() == '.' || name.front() == '-') {
    return Fail(why, "expected a log name starting with a letter, digit or '_', found " +
                         Show(name.front()));
  }
  if (name.find("..") != std::string_view::npos) {
    return Fail(why, "expected a plain file name, found \"..\" in \"" + std::string(name) + "\"");
  }
  if (name.size() <= kSuffix.size() || !name.ends_with(kSuffix)) {
    return Fail(why, "expected a name ending in \".mcap\" after at least one character, found \"" +
                         std::string(name) + "\"");
  }
  return true;
}

}  // namespace rover::log
