#include "firmware/runtime/log_service/http_range.h"

#include <algorithm>
#include <limits>
#include <optional>

namespace rover::runtime {
namespace {

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

std::optional<uint64_t> Digits(std::string_view s) {
  if (s.empty()) return std::nullopt;
  uint64_t v = 0;
  for (const char c : s) {
    if (c < '0' || c > '9') return std::nullopt;
    const auto d = static_cast<uint64_t>(c - '0');
    if (v > (std::numeric_limits<uint64_t>::max() - d) / 10) return std::nullopt;
    v = v * 10 + d;
  }
  return v;
}

bool StartsWithBytesUnit(std::string_view s) {
  constexpr std::string_view kUnit = "bytes=";
  if (s.size() < kUnit.size()) return false;
  for (size_t i = 0; i < kUnit.size(); ++i) {
    const char c = s[i] >= 'A' && s[i] <= 'Z' ? static_cast<char>(s[i] - 'A' + 'a') : s[i];
    if (c != kUnit[i]) return false;
  }
  return true;
}

}  // namespace

ByteRangeRequest ParseRangeHeader(std::string_view header, uint64_t size_bytes) {
  using Kind = ByteRangeRequest::Kind;
  const ByteRangeRequest whole;
  const ByteRangeRequest unsatisfiable{Kind::kUnsatisfiable, 0, 0};
  header = Trim(header);
  if (!StartsWithBytesUnit(header)) return whole;
  const std::string_view spec = Trim(header.substr(6));
  if (spec.find(',') != std::string_view::npos) return whole;
  const size_t dash = spec.find('-');
  if (dash == std::string_view::npos) return whole;
  const std::string_view first_text = Trim(spec.substr(0, dash));
  const std::string_view last_text = Trim(spec.substr(dash + 1));

  if (first_text.empty()) {  // bytes=-n: the last n bytes
    const std::optional<uint64_t> suffix = Digits(last_text);
    if (!suffix) return whole;
    if (*suffix == 0 || size_bytes == 0) return unsatisfiable;
    const uint64_t length = std::min(*suffix, size_bytes);
    return {Kind::kPartial, size_bytes - length, length};
  }
  const std::optional<uint64_t> first = Digits(first_text);
  if (!first) return whole;
  uint64_t last = std::numeric_limits<uint64_t>::max();
  if (!last_text.empty()) {
    const std::optional<uint64_t> parsed = Digits(last_text);
    if (!parsed || *parsed < *first) return whole;
    last = *parsed;
  }
  if (*first >= size_bytes) return unsatisfiable;
  last = std::min(last, size_bytes - 1);
  return {Kind::kPartial, *first, last - *first + 1};
}

}  // namespace rover::runtime
