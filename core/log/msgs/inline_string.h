#ifndef ROVER_CORE_LOG_MSGS_INLINE_STRING_H_
#define ROVER_CORE_LOG_MSGS_INLINE_STRING_H_

// A bounded string stored inline, for message fields that travel through the
// real-time path (frame ids). Unlike std::string it never allocates and is
// trivially copyable, so messages holding it can be memcpy'd through lock-free
// rings and shared memory.
//
// Invariants: at most N chars, no embedded NUL, always NUL-terminated, and all
// bytes after the terminator are zero (so the object's bytes are a pure
// function of its value: defaulted == is exact and no stale data is leaked
// when the raw bytes cross a process boundary).

#include <array>
#include <cstddef>
#include <optional>
#include <string_view>

namespace rover::log {

template <size_t N>
class InlineString {
 public:
  /// Maximum number of characters (excluding the terminating NUL).
  static constexpr size_t kCapacity = N;

  constexpr InlineString() noexcept = default;

  /// Implicit construction from a string literal, checked at compile time:
  /// `header.frame_id = "body";` compiles only if the literal fits.
  template <size_t M>
  requires(M >= 1 && M - 1 <= N) consteval InlineString(
      const char (&literal)[M]) {  // NOLINT(google-explicit-constructor)
    if (!Assign(std::string_view(literal, M - 1))) {
      throw "InlineString literal contains an embedded NUL";  // Compile-time error.
    }
  }

  /// Returns `text` as an InlineString, or nullopt if it is longer than N or
  /// contains a NUL character.
  static constexpr std::optional<InlineString> FromString(std::string_view text) noexcept {
    InlineString result;
    if (!result.Assign(text)) return std::nullopt;
    return result;
  }

  /// Returns `text` cut at its first NUL and then to at most N bytes. The cut
  /// never splits a UTF-8 multi-byte sequence, so the result may be shorter
  /// than N. Use when losing the tail is acceptable (e.g. diagnostics).
  static constexpr InlineString Truncated(std::string_view text) noexcept {
    text = text.substr(0, text.find('\0'));
    if (text.size() > N) {
      size_t cut = N;
      // Back off over UTF-8 continuation bytes (10xxxxxx) at the cut point.
      while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0u) == 0x80u) --cut;
      text = text.substr(0, cut);
    }
    InlineString result;
    result.Assign(text);
    return result;
  }

  /// Replaces the contents with `text` and returns true, or returns false and
  /// leaves the contents unchanged if `text` is longer than N or contains NUL.
  constexpr bool Assign(std::string_view text) noexcept {
    if (text.size() > N || text.find('\0') != std::string_view::npos) return false;
    size_t i = 0;
    for (; i < text.size(); ++i) chars_[i] = text[i];
    for (; i < chars_.size(); ++i) chars_[i] = '\0';
    return true;
  }

  constexpr void clear() noexcept { chars_.fill('\0'); }
  constexpr size_t size() const noexcept { return std::char_traits<char>::length(chars_.data()); }
  constexpr bool empty() const noexcept { return chars_[0] == '\0'; }
  constexpr std::string_view view() const noexcept { return {chars_.data(), size()}; }
  constexpr const char* c_str() const noexcept { return chars_.data(); }

  friend constexpr bool operator==(const InlineString&, const InlineString&) = default;

 private:
  std::array<char, N + 1> chars_{};
};

/// Coordinate frame name (ROS `frame_id`), 63 chars + NUL = 64 bytes.
using FrameId = InlineString<63>;

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_MSGS_INLINE_STRING_H_
