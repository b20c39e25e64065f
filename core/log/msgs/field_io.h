#ifndef ROVER_CORE_LOG_MSGS_FIELD_IO_H_
#define ROVER_CORE_LOG_MSGS_FIELD_IO_H_

// CDR helpers shared by the message serialisers (internal to core/log/msgs).

#include <cstddef>
#include <string>
#include <string_view>

#include "core/log/cdr/cdr_reader.h"
#include "core/log/msgs/inline_string.h"

namespace rover::log::internal {

/// Reads a CDR string into a bounded inline string. Fails, naming `field`, if
/// the string is longer than N or contains an embedded NUL, rather than
/// silently truncating a frame id.
template <size_t N>
bool ReadInlineString(CdrReader& reader, std::string_view field, InlineString<N>* out) {
  std::string_view text;
  if (!reader.ReadStringView(field, &text)) return false;
  // Report the offset of the length prefix: 4 bytes + chars + NUL back.
  const size_t at = reader.offset() - text.size() - 5;
  if (text.size() > N) {
    return reader.Fail(at, field,
                       "string of " + std::to_string(text.size()) +
                           " bytes exceeds the inline capacity of " + std::to_string(N));
  }
  // Assign can only fail on an embedded NUL here (the length fits).
  if (!out->Assign(text)) return reader.Fail(at, field, "string contains an embedded NUL");
  return true;
}

}  // namespace rover::log::internal

#endif  // ROVER_CORE_LOG_MSGS_FIELD_IO_H_
