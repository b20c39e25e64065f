#include "core/log/schema/dynamic_decoder.h"

#include <cstdio>

#include "core/log/cdr/cdr_reader.h"

namespace rover::log {
namespace {

bool IsByteLike(FieldKind kind) {
  return kind == FieldKind::kUint8 || kind == FieldKind::kByte || kind == FieldKind::kChar ||
         kind == FieldKind::kInt8;
}

// Reads one primitive of `kind`; strings included.
bool ReadPrimitive(CdrReader& r, FieldKind kind, FlatField* f) {
  switch (kind) {
    case FieldKind::kBool: {
      bool v = false;
      if (!r.ReadBool("", &v)) return false;
      f->value = v;
      return true;
    }
    case FieldKind::kByte:
    case FieldKind::kChar:
    case FieldKind::kUint8: {
      uint8_t v = 0;
      if (!r.ReadU8("", &v)) return false;
      f->value = uint64_t{v};
      return true;
    }
    case FieldKind::kInt8: {
      int8_t v = 0;
      if (!r.ReadI8("", &v)) return false;
      f->value = int64_t{v};
      return true;
    }
    case FieldKind::kUint16: {
      uint16_t v = 0;
      if (!r.ReadU16("", &v)) return false;
      f->value = uint64_t{v};
      return true;
    }
    case FieldKind::kInt16: {
      int16_t v = 0;
      if (!r.ReadI16("", &v)) return false;
      f->value = int64_t{v};
      return true;
    }
    case FieldKind::kUint32: {
      uint32_t v = 0;
      if (!r.ReadU32("", &v)) return false;
      f->value = uint64_t{v};
      return true;
    }
    case FieldKind::kInt32: {
      int32_t v = 0;
      if (!r.ReadI32("", &v)) return false;
      f->value = int64_t{v};
      return true;
    }
    case FieldKind::kUint64: {
      uint64_t v = 0;
      if (!r.ReadU64("", &v)) return false;
      f->value = v;
      return true;
    }
    case FieldKind::kInt64: {
      int64_t v = 0;
      if (!r.ReadI64("", &v)) return false;
      f->value = v;
      return true;
    }
    case FieldKind::kFloat32: {
      float v = 0;
      if (!r.ReadF32("", &v)) return false;
      f->value = static_cast<double>(v);
      return true;
    }
    case FieldKind::kFloat64: {
      double v = 0;
      if (!r.ReadF64("", &v)) return false;
      f->value = v;
      return true;
    }
    case FieldKind::kString: {
      std::string v;
      if (!r.ReadString("", &v)) return false;
      f->value = std::move(v);
      return true;
    }
    case FieldKind::kWString:
      return r.Fail(r.offset(), "", "wstring fields are not supported");
    case FieldKind::kMessage:
      break;
  }
  return r.Fail(r.offset(), "", "internal: not a primitive");
}

}  // namespace

std::string FormatValue(const FlatField& field) {
  struct Visitor {
    std::string operator()(bool v) const { return v ? "true" : "false"; }
    std::string operator()(int64_t v) const { return std::to_string(v); }
    std::string operator()(uint64_t v) const { return std::to_string(v); }
    std::string operator()(double v) const {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%.17g", v);
      return buf;
    }
    std::string operator()(const std::string& v) const { return v; }
  };
  return std::visit(Visitor{}, field.value);
}

DynamicDecoder::DynamicDecoder(const Ros2MsgSchema& schema, DynamicDecoderOptions options)
    : schema_(schema), options_(options) {}

bool DynamicDecoder::Decode(std::span<const std::byte> cdr, std::vector<FlatField>* out,
                            std::string* error, std::size_t* consumed_bytes) const {
  out->clear();
  CdrReader reader(cdr, schema_.root().name);
  if (reader.ok()) DecodeMessage(reader, schema_.root(), "", out);
  if (!reader.ok()) {
    if (error != nullptr) *error = reader.error();
    return false;
  }
  if (consumed_bytes != nullptr) *consumed_bytes = reader.offset();
  return true;
}

bool DynamicDecoder::DecodeMessage(CdrReader& reader, const MessageDefinition& type,
                                   const std::string& prefix, std::vector<FlatField>* out) const {
  for (const FieldDefinition& field : type.fields) {
    const CdrReader::Scope scope = reader.EnterField(field.name);
    const std::string path = prefix.empty() ? field.name : prefix + "." + field.name;
    if (!DecodeField(reader, field, path, out)) return false;
  }
  return true;
}

bool DynamicDecoder::DecodeField(CdrReader& reader, const FieldDefinition& field,
                                 const std::string& path, std::vector<FlatField>* out) const {
  if (field.array == ArrayKind::kScalar) return DecodeOne(reader, field, path, out);
  std::size_t count = field.array_size;
  if (field.array != ArrayKind::kFixed) {
    const std::size_t min_size = std::max<std::size_t>(1, PrimitiveSize(field.kind));
    if (!reader.ReadSequenceSize("", min_size, &count)) return false;
    if (field.array == ArrayKind::kBounded && count > field.array_size) {
      return reader.Fail(reader.offset(), "",
                         "sequence of " + std::to_string(count) + " elements exceeds its bound " +
                             std::to_string(field.array_size));
    }
  }
  if (IsByteLike(field.kind) && count > options_.max_byte_array_elements) {
    // Consume the bytes but report only their number (pixels are not text).
    for (std::size_t i = 0; i < count; ++i) {
      uint8_t ignored = 0;
      if (!reader.ReadU8("", &ignored)) return false;
    }
    out->push_back({path, std::to_string(count) + " bytes"});
    return true;
  }
  for (std::size_t i = 0; i < count; ++i) {
    const CdrReader::Scope element = reader.EnterElement(i);
    if (!DecodeOne(reader, field, path + "[" + std::to_string(i) + "]", out)) return false;
  }
  return true;
}

bool DynamicDecoder::DecodeOne(CdrReader& reader, const FieldDefinition& field,
                               const std::string& path, std::vector<FlatField>* out) const {
  if (field.kind == FieldKind::kMessage) {
    return DecodeMessage(reader, schema_.Type(field.type_name), path, out);
  }
  FlatField flat{path, {}};
  if (!ReadPrimitive(reader, field.kind, &flat)) return false;
  out->push_back(std::move(flat));
  return true;
}

}  // namespace rover::log
