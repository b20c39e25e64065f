#ifndef ROVER_ESTIMATOR_EVAL_TEXT_TABLE_READER_H_
#define ROVER_ESTIMATOR_EVAL_TEXT_TABLE_READER_H_

// Line-by-line reader for the text trajectory formats (TUM, EuRoC CSV,
// OpenVINS CSV), shared by their readers. It keeps the line number so every
// problem is reported as "FILE:LINE: expected ..., found ...".

#include <cstdint>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include "core/time/time.h"

namespace rover::eval {

class TextTableReader {
 public:
  enum class Separator {
    kComma,       ///< Cells split at ',' and trimmed (CSV).
    kWhitespace,  ///< Cells split at runs of spaces and tabs (TUM).
  };

  /// Opens `path`; throws EvalError ("PATH: cannot open ...") if it cannot.
  TextTableReader(std::string path, Separator separator);

  /// Reads the next non-empty line. Comment lines (first non-blank character
  /// '#') are returned too when `comments` is true, otherwise skipped. The
  /// cells of a comment line exclude the '#'. Returns false at end of file.
  bool Next(std::vector<std::string_view>* cells, bool comments = false);
  /// True if the line returned last by Next() was a comment.
  bool is_comment() const { return is_comment_; }
  /// The line returned last by Next(), trimmed.
  std::string_view line() const { return line_view_; }
  int line_number() const { return line_number_; }
  const std::string& path() const { return path_; }

  /// Throws EvalError("PATH:LINE: " + what).
  [[noreturn]] void Fail(const std::string& what) const;

  /// Parses a finite double; fails with "expected a number for COLUMN, found 'CELL'".
  double Double(std::string_view cell, std::string_view column) const;
  /// Parses an integer; fails like Double().
  int64_t Int64(std::string_view cell, std::string_view column) const;
  /// Parses a time in seconds given as a decimal number ("1403715273.262142976"),
  /// exactly to the nanosecond when written without exponent (digits beyond the
  /// ninth decimal are rounded); exponent forms go through a double.
  Time Seconds(std::string_view cell, std::string_view column) const;
  /// Parses an integer time in nanoseconds.
  Time Nanoseconds(std::string_view cell, std::string_view column) const;

 private:
  std::string path_;
  Separator separator_;
  std::ifstream in_;
  std::string line_;
  std::string_view line_view_;
  int line_number_ = 0;
  bool is_comment_ = false;
};

/// Parses decimal seconds exactly into nanoseconds (see TextTableReader::Seconds);
/// returns false if `text` is not a finite number in range.
bool ParseSecondsAsTime(std::string_view text, Time* time);

}  // namespace rover::eval

#endif  // ROVER_ESTIMATOR_EVAL_TEXT_TABLE_READER_H_
