#include "core/cli/report_format.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace rover::cli {

std::string Fixed(double value, int decimals) {
  if (std::isnan(value)) return "nan";
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  return buffer;
}

std::string General(double value, int significant) {
  if (std::isnan(value)) return "nan";
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*g", significant, value);
  return buffer;
}

TextTable::TextTable(std::vector<std::string> header) { rows_.push_back(std::move(header)); }

void TextTable::AddRow(std::vector<std::string> cells) {
  if (cells.size() != rows_.front().size()) {
    throw std::logic_error("TextTable: row has " + std::to_string(cells.size()) +
                           " cells, header " + std::to_string(rows_.front().size()));
  }
  rows_.push_back(std::move(cells));
}

std::string TextTable::ToString() const {
  std::vector<std::size_t> width(rows_.front().size(), 0);
  for (const auto& row : rows_) {
    for (std::size_t c = 0; c < row.size(); ++c) width[c] = std::max(width[c], row[c].size());
  }
  std::string text;
  for (const auto& row : rows_) {
    std::string line = " ";
    for (std::size_t c = 0; c < row.size(); ++c) {
      const std::string pad(width[c] - row[c].size(), ' ');
      line += "  ";
      line += c == 0 ? row[c] + pad : pad + row[c];
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    text += line + "\n";
  }
  return text;
}

std::string ResultLine(const std::vector<std::pair<std::string, std::string>>& fields) {
  std::string line = "RESULT";
  for (const auto& [key, value] : fields) line += " " + key + "=" + value;
  return line;
}

}  // namespace rover::cli
