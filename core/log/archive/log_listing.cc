#include "core/log/archive/log_listing.h"

#include <limits>

#include "core/log/archive/log_name.h"

namespace rover::log {
namespace {

constexpr int kMaxDepth = 32;

void AppendEscaped(std::string& out, std::string_view text) {
  static constexpr char kHex[] = "0123456789abcdef";
  out.push_back('"');
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (u < 0x20) {
          out += "\\u00";
          out.push_back(kHex[u >> 4]);
          out.push_back(kHex[u & 0x0F]);
        } else {
          out.push_back(c);
        }
    }
  }
  out.push_back('"');
}

void AppendOptional(std::string& out, const std::optional<uint64_t>& value) {
  out += value ? std::to_string(*value) : "null";
}

bool IsLowerHex(std::string_view s) {
  for (const char c : s) {
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  }
  return true;
}

// Recursive-descent reader over the listing text; every error names the byte
// offset, what was expected and what was found.
class Parser {
 public:
  explicit Parser(std::string_view text) : text_(text) {}

  std::vector<LogListingEntry> Listing() {
    std::vector<LogListingEntry> entries;
    Expect('[', "'[' starting the listing array");
    SkipSpace();
    if (Peek() == ']') {
      ++pos_;
    } else {
      for (;;) {
        entries.push_back(Entry());
        SkipSpace();
        if (Peek() == ',') {
          ++pos_;
          continue;
        }
        Expect(']', "',' or ']' after a listing entry");
        break;
      }
    }
    SkipSpace();
    if (pos_ != text_.size()) Fail("the end of the listing after ']'");
    return entries;
  }

 private:
  LogListingEntry Entry() {
    LogListingEntry entry;
    bool has_name = false, has_size = false, has_sha = false, has_complete = false;
    const size_t start = pos_;
    Expect('{', "'{' starting a listing entry");
    SkipSpace();
    if (Peek() == '}') {
      ++pos_;
    } else {
      for (;;) {
        SkipSpace();
        const std::string key = String();
        Expect(':', "':' after the key \"" + key + "\"");
        SkipSpace();
        if (key == "name") {
          entry.name = String();
          std::string why;
          if (!IsValidLogName(entry.name, &why)) Fail("a valid log name: " + why, start);
          has_name = true;
        } else if (key == "size_bytes") {
          entry.size_bytes = Unsigned("size_bytes");
          has_size = true;
        } else if (key == "start_time_ns") {
          entry.start_time_ns = OptionalUnsigned("start_time_ns");
        } else if (key == "end_time_ns") {
          entry.end_time_ns = OptionalUnsigned("end_time_ns");
        } else if (key == "sha256") {
          const size_t at = pos_;
          entry.sha256 = String();
          if (entry.sha256.size() != 64 || !IsLowerHex(entry.sha256)) {
            Fail("sha256 as 64 lowercase hex characters", at);
          }
          has_sha = true;
        } else if (key == "complete") {
          entry.complete = Bool("complete");
          has_complete = true;
        } else {
          SkipValue(1);
        }
        SkipSpace();
        if (Peek() == ',') {
          ++pos_;
          continue;
        }
        Expect('}', "',' or '}' in a listing entry");
        break;
      }
    }
    const char* missing = !has_name       ? "name"
                          : !has_size     ? "size_bytes"
                          : !has_sha      ? "sha256"
                          : !has_complete ? "complete"
                                          : nullptr;
    if (missing != nullptr) {
      throw LogListingError("log listing: expected the key \"" + std::string(missing) +
                            "\" in the entry at offset " + std::to_string(start) +
                            ", found an entry without it");
    }
    return entry;
  }

  void SkipSpace() {
    while (pos_ < text_.size() && (text_[pos_] == ' ' || text_[pos_] == '\n' ||
                                   text_[pos_] == '\r' || text_[pos_] == '\t')) {
      ++pos_;
    }
  }

  char Peek() const { return pos_ < text_.size() ? text_[pos_] : '\0'; }

  void Expect(char c, const std::string& what) {
    SkipSpace();
    if (Peek() != c || pos_ >= text_.size()) Fail(what);
    ++pos_;
  }

  std::string Found(size_t at) const {
    if (at >= text_.size()) return "the end of the text";
    const auto u = static_cast<unsigned char>(text_[at]);
    if (u >= 0x20 && u < 0x7F) return std::string("'") + text_[at] + "'";
    return "byte " + std::to_string(u);
  }

  [[noreturn]] void Fail(const std::string& expected) const { Fail(expected, pos_); }
  [[noreturn]] void Fail(const std::string& expected, size_t at) const {
    throw LogListingError("log listing: expected " + expected + " at offset " + std::to_string(at) +
                          ", found " + Found(at));
  }

  static int HexValue(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
  }

  uint32_t Hex4() {
    uint32_t v = 0;
    for (int i = 0; i < 4; ++i) {
      const int h = HexValue(Peek());
      if (h < 0 || pos_ >= text_.size()) Fail("4 hex digits after \\u");
      v = (v << 4) | static_cast<uint32_t>(h);
      ++pos_;
    }
    return v;
  }

  static void AppendUtf8(std::string& out, uint32_t cp) {
    if (cp < 0x80) {
      out.push_back(static_cast<char>(cp));
    } else if (cp < 0x800) {
      out.push_back(static_cast<char>(0xC0 | (cp >> 6)));
      out.push_back(static_cast<char>(0x80 | (cp & 0x3F)));
    } else if (cp < 0x10000) {
      out.push_back(static_cast<char>(0xE0 | (cp >> 12)));
      out.push_back(static_cast<char>(0x80 | ((cp >> 6) & 0x3F)));
      out.push_back(static_cast<char>(0x80 | (cp & 0x3F)));
    } else {
      out.push_back(static_cast<char>(0xF0 | (cp >> 18)));
      out.push_back(static_cast<char>(0x80 | ((cp >> 12) & 0x3F)));
      out.push_back(static_cast<char>(0x80 | ((cp >> 6) & 0x3F)));
      out.push_back(static_cast<char>(0x80 | (cp & 0x3F)));
    }
  }

  std::string String() {
    SkipSpace();
    if (Peek() != '"' || pos_ >= text_.size()) Fail("a string");
    ++pos_;
    std::string out;
    for (;;) {
      if (pos_ >= text_.size()) Fail("'\"' closing the string");
      const char c = text_[pos_];
      if (c == '"') {
        ++pos_;
        return out;
      }
      if (static_cast<unsigned char>(c) < 0x20) Fail("no control characters inside a string");
      if (c != '\\') {
        out.push_back(c);
        ++pos_;
        continue;
      }
      ++pos_;
      const char e = Peek();
      if (pos_ >= text_.size()) Fail("an escape character after '\\'");
      ++pos_;
      switch (e) {
        case '"':
        case '\\':
        case '/':
          out.push_back(e);
          break;
        case 'b':
          out.push_back('\b');
          break;
        case 'f':
          out.push_back('\f');
          break;
        case 'n':
          out.push_back('\n');
          break;
        case 'r':
          out.push_back('\r');
          break;
        case 't':
          out.push_back('\t');
          break;
        case 'u': {
          uint32_t cp = Hex4();
          if (cp >= 0xD800 && cp <= 0xDBFF) {
            if (Peek() != '\\' || pos_ + 1 >= text_.size() || text_[pos_ + 1] != 'u') {
              Fail("a low surrogate \\uDC00-\\uDFFF after a high surrogate");
            }
            pos_ += 2;
            const uint32_t low = Hex4();
            if (low < 0xDC00 || low > 0xDFFF) Fail("a low surrogate \\uDC00-\\uDFFF", pos_ - 4);
            cp = 0x10000 + ((cp - 0xD800) << 10) + (low - 0xDC00);
          } else if (cp >= 0xDC00 && cp <= 0xDFFF) {
            Fail("no lone low surrogate", pos_ - 4);
          }
          AppendUtf8(out, cp);
          break;
        }
        default:
          Fail("one of \\\" \\\\ \\/ \\b \\f \\n \\r \\t \\u", pos_ - 1);
      }
    }
  }

  uint64_t Unsigned(const char* key) {
    SkipSpace();
    const size_t start = pos_;
    uint64_t v = 0;
    while (pos_ < text_.size() && text_[pos_] >= '0' && text_[pos_] <= '9') {
      const auto digit = static_cast<uint64_t>(text_[pos_] - '0');
      if (v > (std::numeric_limits<uint64_t>::max() - digit) / 10) {
        Fail(std::string(key) + " within 0..18446744073709551615", start);
      }
      v = v * 10 + digit;
      ++pos_;
    }
    if (pos_ == start) Fail(std::string(key) + " as a non-negative integer");
    if (pos_ - start > 1 && text_[start] == '0')
      Fail("no leading zeros in " + std::string(key), start);
    const char next = Peek();
    if (next == '.' || next == 'e' || next == 'E') {
      Fail(std::string(key) + " as a non-negative integer (no fraction or exponent)");
    }
    return v;
  }

  std::optional<uint64_t> OptionalUnsigned(const char* key) {
    SkipSpace();
    if (text_.substr(pos_).starts_with("null")) {
      pos_ += 4;
      return std::nullopt;
    }
    return Unsigned(key);
  }

  bool Bool(const char* key) {
    SkipSpace();
    if (text_.substr(pos_).starts_with("true")) {
      pos_ += 4;
      return true;
    }
    if (text_.substr(pos_).starts_with("false")) {
      pos_ += 5;
      return false;
    }
    Fail(std::string(key) + " as true or false");
  }

  void SkipValue(int depth) {
    if (depth > kMaxDepth) Fail("values nested at most " + std::to_string(kMaxDepth) + " deep");
    SkipSpace();
    const char c = Peek();
    if (pos_ >= text_.size()) Fail("a value");
    if (c == '"') {
      String();
    } else if (c == '{' || c == '[') {
      const char close = c == '{' ? '}' : ']';
      ++pos_;
      SkipSpace();
      if (Peek() == close) {
        ++pos_;
        return;
      }
      for (;;) {
        if (c == '{') {
          String();
          Expect(':', "':' after an object key");
        }
        SkipValue(depth + 1);
        SkipSpace();
        if (Peek() == ',') {
          ++pos_;
          continue;
        }
        Expect(close, std::string("',' or '") + close + "'");
        return;
      }
    } else if (text_.substr(pos_).starts_with("true")) {
      pos_ += 4;
    } else if (text_.substr(pos_).starts_with("false")) {
      pos_ += 5;
    } else if (text_.substr(pos_).starts_with("null")) {
      pos_ += 4;
    } else if (c == '-' || (c >= '0' && c <= '9')) {
      ++pos_;
      while (pos_ < text_.size() &&
             ((text_[pos_] >= '0' && text_[pos_] <= '9') || text_[pos_] == '.' ||
              text_[pos_] == 'e' || text_[pos_] == 'E' || text_[pos_] == '+' ||
              text_[pos_] == '-')) {
        ++pos_;
      }
    } else {
      Fail("a JSON value");
    }
  }

  std::string_view text_;
  size_t pos_ = 0;
};

}  // namespace

std::string LogListingToJson(const std::vector<LogListingEntry>& entries) {
  std::string out = "[";
  for (size_t i = 0; i < entries.size(); ++i) {
    const LogListingEntry& e = entries[i];
    out += i == 0 ? "\n" : ",\n";
    out += "{\"name\": ";
    AppendEscaped(out, e.name);
    out += ", \"size_bytes\": " + std::to_string(e.size_bytes);
    out += ", \"start_time_ns\": ";
    AppendOptional(out, e.start_time_ns);
    out += ", \"end_time_ns\": ";
    AppendOptional(out, e.end_time_ns);
    out += ", \"sha256\": ";
    AppendEscaped(out, e.sha256);
    out += ", \"complete\": ";
    out += e.complete ? "true" : "false";
    out += "}";
  }
  out += entries.empty() ? "]\n" : "\n]\n";
  return out;
}

std::vector<LogListingEntry> ParseLogListingJson(std::string_view json) {
  return Parser(json).Listing();
}

}  // namespace rover::log
