#ifndef ROVER_CORE_LOG_SCHEMA_DYNAMIC_DECODER_H_
#define ROVER_CORE_LOG_SCHEMA_DYNAMIC_DECODER_H_

// Decodes CDR messages of any type described by a ros2msg schema into a flat
// list of named leaf values ("header.stamp.sec", "transforms[1].child_frame_id").
// This is how host tools export or print topics they were not compiled
// against, the way a generic viewer would.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "core/log/schema/ros2msg_schema.h"

namespace rover::log {

class CdrReader;

/// One decoded leaf.
struct FlatField {
  std::string path;
  std::variant<bool, int64_t, uint64_t, double, std::string> value;
};

/// Formats a value for text output: integers exactly, float64 with 17
/// significant digits (round-trips), strings as they are.
std::string FormatValue(const FlatField& field);

struct DynamicDecoderOptions {
  /// uint8/byte/char sequences and arrays longer than this (image pixels) are
  /// summarised as one field "<path>" = "<N bytes>" instead of N fields.
  std::size_t max_byte_array_elements = 64;
};

class DynamicDecoder {
 public:
  /// `schema` must outlive the decoder.
  explicit DynamicDecoder(const Ros2MsgSchema& schema, DynamicDecoderOptions options = {});

  /// Decodes one serialized message (with its 4-byte encapsulation header)
  /// into `out` (cleared first). Returns false and sets `error` to a message
  /// naming the field and byte offset if the bytes do not match the schema.
  /// `consumed_bytes`, if given, receives how many bytes the message took;
  /// fewer than `cdr.size()` hints at a schema that does not match the data.
  bool Decode(std::span<const std::byte> cdr, std::vector<FlatField>* out, std::string* error,
              std::size_t* consumed_bytes = nullptr) const;

 private:
  bool DecodeMessage(CdrReader& reader, const MessageDefinition& type, const std::string& prefix,
                     std::vector<FlatField>* out) const;
  bool DecodeField(CdrReader& reader, const FieldDefinition& field, const std::string& path,
                   std::vector<FlatField>* out) const;
  bool DecodeOne(CdrReader& reader, const FieldDefinition& field, const std::string& path,
                 std::vector<FlatField>* out) const;

  const Ros2MsgSchema& schema_;
  DynamicDecoderOptions options_;
};

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_SCHEMA_DYNAMIC_DECODER_H_
