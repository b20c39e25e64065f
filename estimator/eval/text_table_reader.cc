#include "estimator/eval/text_table_reader.h"

#include <charconv>
#include <cmath>
#include <limits>

#include "estimator/eval/eval_error.h"

namespace rover::eval {
namespace {

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) {
    s.remove_suffix(1);
  }
  return s;
}

bool AllDigits(std::string_view s) {
  for (const char c : s) {
    if (c < '0' || c > '9') return false;
  }
  return true;
}

}  // namespace

bool ParseSecondsAsTime(std::string_view text, Time* time) {
  std::string_view s = text;
  bool negative = false;
  if (!s.empty() && (s.front() == '-' || s.front() == '+')) {
    negative = s.front() == '-';
    s.remove_prefix(1);
  }
  const std::size_t dot = s.find('.');
  const std::string_view whole = s.substr(0, dot);
  const std::string_view fraction =
      dot == std::string_view::npos ? std::string_view() : s.substr(dot + 1);
  if (!whole.empty() && whole.size() <= 10 && AllDigits(whole) && AllDigits(fraction) &&
      (!whole.empty() || !fraction.empty())) {
    int64_t seconds = 0;
    for (const char c : whole) seconds = seconds * 10 + (c - '0');
    if (seconds > 9'223'372'035) return false;  // Beyond the int64 nanosecond range.
    int64_t nanos = 0;
    for (std::size_t i = 0; i < 9; ++i) {
      nanos = nanos * 10 + (i < fraction.size() ? fraction[i] - '0' : 0);
    }
    if (fraction.size() > 9 && fraction[9] >= '5') ++nanos;  // round half up
    int64_t ns = seconds * 1'000'000'000 + nanos;
    *time = Time::FromNanoseconds(negative ? -ns : ns);
    return true;
  }
  // Exponent notation and other forms: through a double.
  double value = 0.0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || ptr != text.data() + text.size() || !std::isfinite(value) ||
      std::abs(value) > 9.2e9) {
    return false;
  }
  *time = Time::FromSeconds(value);
  return true;
}

TextTableReader::TextTableReader(std::string path, Separator separator)
    : path_(std::move(path)), separator_(separator), in_(path_) {
  if (!in_) throw EvalError(path_ + ": cannot open (no such file or not readable)");
}

bool TextTableReader::Next(std::vector<std::string_view>* cells, bool comments) {
  while (std::getline(in_, line_)) {
    ++line_number_;
    std::string_view line = Trim(line_);
    if (line.empty()) continue;
    is_comment_ = line.front() == '#';
    if (is_comment_ && !comments) continue;
    line_view_ = line;
    if (is_comment_) line = Trim(line.substr(1));
    cells->clear();
    if (separator_ == Separator::kComma) {
      std::size_t start = 0;
      for (std::size_t comma; (comma = line.find(',', start)) != std::string_view::npos;) {
        cells->push_back(Trim(line.substr(start, comma - start)));
        start = comma + 1;
      }
      cells->push_back(Trim(line.substr(start)));
    } else {
      std::size_t i = 0;
      while (i < line.size()) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
        const std::size_t start = i;
        while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
        if (i > start) cells->push_back(line.substr(start, i - start));
      }
    }
    return true;
  }
  return false;
}

void TextTableReader::Fail(const std::string& what) const {
  throw EvalError(path_ + ":" + std::to_string(line_number_) + ": " + what);
}

double TextTableReader::Double(std::string_view cell, std::string_view column) const {
  double value = 0.0;
  const char* begin = cell.data();
  if (!cell.empty() && cell.front() == '+') ++begin;
  const auto [ptr, ec] = std::from_chars(begin, cell.data() + cell.size(), value);
  if (cell.empty() || ec != std::errc() || ptr != cell.data() + cell.size() ||
      !std::isfinite(value)) {
    Fail("expected a finite number for " + std::string(column) + ", found '" + std::string(cell) +
         "'");
  }
  return value;
}

int64_t TextTableReader::Int64(std::string_view cell, std::string_view column) const {
  int64_t value = 0;
  const auto [ptr, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), value);
  if (cell.empty() || ec != std::errc() || ptr != cell.data() + cell.size()) {
    Fail("expected an integer for " + std::string(column) + ", found '" + std::string(cell) + "'");
  }
  return value;
}

Time TextTableReader::Seconds(std::string_view cell, std::string_view column) const {
  Time t;
  if (!ParseSecondsAsTime(cell, &t)) {
    Fail("expected a time in seconds for " + std::string(column) + ", found '" + std::string(cell) +
         "'");
  }
  return t;
}

Time TextTableReader::Nanoseconds(std::string_view cell, std::string_view column) const {
  return Time::FromNanoseconds(Int64(cell, column));
}

}  // namespace rover::eval
