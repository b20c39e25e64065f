#ifndef ROVER_CORE_CLI_REPORT_FORMAT_H_
#define ROVER_CORE_CLI_REPORT_FORMAT_H_

// Text formatting shared by the command-line tools: fixed-width tables
// and the machine-readable "RESULT key=value ..." line.

#include <string>
#include <utility>
#include <vector>

namespace rover::cli {

/// `value` with `decimals` digits after the point ("%.*f"); "nan" for NaN.
std::string Fixed(double value, int decimals);

/// `value` in "%.*g" form (significant digits); "nan" for NaN, "inf" for infinity.
std::string General(double value, int significant = 6);

/// A table with a header row, printed with right-aligned columns (the first
/// column left-aligned) separated by two spaces and indented by two.
class TextTable {
 public:
  explicit TextTable(std::vector<std::string> header);
  /// Adds a row; it must have as many cells as the header.
  void AddRow(std::vector<std::string> cells);
  /// The table, one line per row, each ending in '\n'.
  std::string ToString() const;

 private:
  std::vector<std::vector<std::string>> rows_;
};

/// "RESULT k1=v1 k2=v2 ..." (no trailing newline). Keys and values must not
/// contain spaces.
std::string ResultLine(const std::vector<std::pair<std::string, std::string>>& fields);

}  // namespace rover::cli

#endif  // ROVER_CORE_CLI_REPORT_FORMAT_H_
