#include "host/eval/can_frames_csv.h"

#include <charconv>
#include <string_view>

#include "estimator/eval/text_table_reader.h"

namespace rover::host::eval {
namespace {

// Hex digits with an optional 0x prefix.
bool ParseHex(std::string_view text, uint32_t* value) {
  if (text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X'))
    text.remove_prefix(2);
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, *value, 16);
  return !text.empty() && ec == std::errc() && ptr == end;
}

}  // namespace

std::vector<drivers::CanFrame> ReadCanFramesCsv(const std::string& path) {
  rover::eval::TextTableReader csv(path, rover::eval::TextTableReader::Separator::kComma);
  std::vector<drivers::CanFrame> frames;
  std::vector<std::string_view> c;
  while (csv.Next(&c)) {
    if (c.size() != 3 && c.size() != 4) {
      csv.Fail("expected 4 columns (timestamp [ns], id, dlc, data_hex), found " +
               std::to_string(c.size()));
    }
    drivers::CanFrame f;
    f.stamp = csv.Nanoseconds(c[0], "timestamp");
    if (!ParseHex(c[1], &f.id) || f.id > 0x7FF) {
      csv.Fail("expected an 11-bit identifier such as 0x181 for id, found '" + std::string(c[1]) +
               "'");
    }
    const int64_t dlc = csv.Int64(c[2], "dlc");
    if (dlc < 0 || dlc > 8) csv.Fail("expected a dlc in [0, 8], found " + std::to_string(dlc));
    f.dlc = static_cast<uint8_t>(dlc);
    const std::string_view hex = c.size() == 4 ? c[3] : std::string_view();
    if (hex.size() != 2 * f.dlc) {
      csv.Fail("expected " + std::to_string(2 * f.dlc) + " hex digits of data for dlc " +
               std::to_string(dlc) + ", found '" + std::string(hex) + "'");
    }
    for (std::size_t b = 0; b < f.dlc; ++b) {
      uint32_t byte = 0;
      if (!ParseHex(hex.substr(2 * b, 2), &byte)) {
        csv.Fail("expected hex digits for data_hex, found '" + std::string(hex) + "'");
      }
      f.data[b] = static_cast<uint8_t>(byte);
    }
    frames.push_back(f);
  }
  return frames;
}

}  // namespace rover::host::eval
