#include "core/log/schema/ros2msg_schema.h"

#include <algorithm>
#include <charconv>
#include <set>

namespace rover::log {
namespace {

std::string_view Trim(std::string_view s) {
  const auto begin = s.find_first_not_of(" \t\r");
  if (begin == std::string_view::npos) return {};
  const auto end = s.find_last_not_of(" \t\r");
  return s.substr(begin, end - begin + 1);
}

// Drops a trailing comment. A '#' inside a quoted default value is kept.
std::string_view StripComment(std::string_view line) {
  char quote = 0;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quote != 0) {
      if (c == quote) quote = 0;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '#') {
      return line.substr(0, i);
    }
  }
  return line;
}

bool IsSeparator(std::string_view line) {
  line = Trim(line);
  return line.size() >= 3 && line.find_first_not_of('=') == std::string_view::npos;
}

std::string PackageOf(const std::string& type_name) {
  return type_name.substr(0, type_name.find('/'));
}

const std::map<std::string_view, FieldKind>& PrimitiveKinds() {
  static const std::map<std::string_view, FieldKind> kinds = {
      {"bool", FieldKind::kBool},       {"byte", FieldKind::kByte},
      {"char", FieldKind::kChar},       {"int8", FieldKind::kInt8},
      {"uint8", FieldKind::kUint8},     {"int16", FieldKind::kInt16},
      {"uint16", FieldKind::kUint16},   {"int32", FieldKind::kInt32},
      {"uint32", FieldKind::kUint32},   {"int64", FieldKind::kInt64},
      {"uint64", FieldKind::kUint64},   {"float32", FieldKind::kFloat32},
      {"float64", FieldKind::kFloat64}, {"string", FieldKind::kString},
      {"wstring", FieldKind::kWString},
  };
  return kinds;
}

class Parser {
 public:
  Parser(std::string type_name, int first_line) : type_(std::move(type_name)), line_(first_line) {}

  [[noreturn]] void Fail(const std::string& what) const {
    throw SchemaError("ros2msg schema, type " + type_ + ", line " + std::to_string(line_) + ": " +
                      what);
  }

  void set_line(int line) { line_ = line; }

  uint32_t ParseCount(std::string_view digits) const {
    uint32_t value = 0;
    const auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (ec != std::errc() || ptr != digits.data() + digits.size() || digits.empty()) {
      Fail("expected an array size, found '" + std::string(digits) + "'");
    }
    return value;
  }

  // Parses "base", "base[]", "base[N]", "base[<=N]" into `field`.
  void ParseType(std::string_view type, FieldDefinition* field) const {
    if (const auto open = type.find('['); open != std::string_view::npos) {
      if (type.back() != ']') Fail("unterminated array type '" + std::string(type) + "'");
      const std::string_view inside = type.substr(open + 1, type.size() - open - 2);
      if (inside.empty()) {
        field->array = ArrayKind::kUnbounded;
      } else if (inside.starts_with("<=")) {
        field->array = ArrayKind::kBounded;
        field->array_size = ParseCount(inside.substr(2));
      } else {
        field->array = ArrayKind::kFixed;
        field->array_size = ParseCount(inside);
      }
      type = type.substr(0, open);
    }
    // Bounded strings ("string<=10") are plain strings on the wire.
    if (const auto bound = type.find("<="); bound != std::string_view::npos) {
      type = type.substr(0, bound);
    }
    const auto& kinds = PrimitiveKinds();
    if (const auto it = kinds.find(type); it != kinds.end()) {
      field->kind = it->second;
      return;
    }
    field->kind = FieldKind::kMessage;
    if (type == "time" || type == "duration") {  // ROS 1 spellings some tools still emit
      field->type_name =
          type == "time" ? "builtin_interfaces/msg/Time" : "builtin_interfaces/msg/Duration";
    } else if (type.find('/') == std::string_view::npos) {
      field->type_name =
          type == "Header" ? "std_msgs/msg/Header" : PackageOf(type_) + "/msg/" + std::string(type);
    } else {
      field->type_name = NormalizeTypeName(type);
    }
  }

  // Parses one non-empty, comment-free line. Returns false for constants
  // ("byte OK=0", "int32 X = 5"), which carry no data on the wire.
  bool ParseLine(std::string_view line, FieldDefinition* field) const {
    const auto type_end = line.find_first_of(" \t");
    if (type_end == std::string_view::npos)
      Fail("expected 'type name', found '" + std::string(line) + "'");
    const std::string_view type = line.substr(0, type_end);
    std::string_view rest = Trim(line.substr(type_end));
    const auto name_end = rest.find_first_of(" \t=");
    const std::string_view name = rest.substr(0, name_end);
    if (name_end != std::string_view::npos && Trim(rest.substr(name_end)).starts_with("=")) {
      return false;
    }
    if (name.empty()) Fail("field of type '" + std::string(type) + "' has no name");
    field->name = std::string(name);
    ParseType(type, field);
    return true;  // anything after the name is a default value, which decoding ignores
  }

 private:
  std::string type_;
  int line_;
};

void CheckResolvable(const std::map<std::string, MessageDefinition>& types, const std::string& name,
                     std::set<std::string>* on_path) {
  if (!on_path->insert(name).second) {
    throw SchemaError("ros2msg schema: type " + name + " contains itself");
  }
  for (const FieldDefinition& field : types.at(name).fields) {
    if (field.kind != FieldKind::kMessage) continue;
    if (!types.contains(field.type_name)) {
      throw SchemaError("ros2msg schema: field '" + field.name + "' of " + name + " has type " +
                        field.type_name + ", which the schema text does not define");
    }
    CheckResolvable(types, field.type_name, on_path);
  }
  on_path->erase(name);
}

// builtin_interfaces are primitives in ROS 2 tooling and often left out of
// the text; define them when the text does not.
void AddBuiltinTypes(std::map<std::string, MessageDefinition>* types) {
  for (const char* name : {"builtin_interfaces/msg/Time", "builtin_interfaces/msg/Duration"}) {
    if (types->contains(name)) continue;
    MessageDefinition def{name, {}};
    def.fields.push_back({"sec", FieldKind::kInt32, "", ArrayKind::kScalar, 0});
    def.fields.push_back({"nanosec", FieldKind::kUint32, "", ArrayKind::kScalar, 0});
    types->emplace(name, std::move(def));
  }
}

}  // namespace

std::string NormalizeTypeName(std::string_view name) {
  const auto slash = name.find('/');
  if (slash == std::string_view::npos) return std::string(name);
  const std::string_view package = name.substr(0, slash);
  std::string_view type = name.substr(name.rfind('/') + 1);
  return std::string(package) + "/msg/" + std::string(type);
}

std::size_t PrimitiveSize(FieldKind kind) {
  switch (kind) {
    case FieldKind::kBool:
    case FieldKind::kByte:
    case FieldKind::kChar:
    case FieldKind::kInt8:
    case FieldKind::kUint8:
      return 1;
    case FieldKind::kInt16:
    case FieldKind::kUint16:
      return 2;
    case FieldKind::kInt32:
    case FieldKind::kUint32:
    case FieldKind::kFloat32:
      return 4;
    case FieldKind::kInt64:
    case FieldKind::kUint64:
    case FieldKind::kFloat64:
      return 8;
    case FieldKind::kString:
    case FieldKind::kWString:
    case FieldKind::kMessage:
      return 0;
  }
  return 0;
}

Ros2MsgSchema Ros2MsgSchema::Parse(std::string_view root_name, std::string_view text) {
  Ros2MsgSchema schema;
  schema.root_name_ = NormalizeTypeName(root_name);
  MessageDefinition current{schema.root_name_, {}};
  Parser parser(current.name, 1);
  bool expect_msg_line = false;
  auto finish = [&]() {
    if (!schema.types_.emplace(current.name, std::move(current)).second) {
      parser.Fail("type defined twice");
    }
  };
  int line_number = 0;
  for (std::size_t pos = 0; pos <= text.size();) {
    const std::size_t newline = std::min(text.find('\n', pos), text.size());
    const std::string_view raw = text.substr(pos, newline - pos);
    pos = newline + 1;
    parser.set_line(++line_number);
    if (IsSeparator(raw)) {
      finish();
      expect_msg_line = true;
      continue;
    }
    const std::string_view line = Trim(StripComment(raw));
    if (line.empty()) continue;
    if (expect_msg_line) {
      if (!line.starts_with("MSG:")) parser.Fail("expected 'MSG: pkg/Type' after a separator");
      current = MessageDefinition{NormalizeTypeName(Trim(line.substr(4))), {}};
      parser = Parser(current.name, line_number);
      expect_msg_line = false;
      continue;
    }
    FieldDefinition field;
    if (parser.ParseLine(line, &field)) current.fields.push_back(std::move(field));
  }
  if (expect_msg_line) parser.Fail("separator not followed by 'MSG: pkg/Type'");
  finish();
  AddBuiltinTypes(&schema.types_);
  std::set<std::string> on_path;
  CheckResolvable(schema.types_, schema.root_name_, &on_path);
  return schema;
}

const MessageDefinition& Ros2MsgSchema::Type(const std::string& name) const {
  const auto it = types_.find(name);
  if (it == types_.end()) throw SchemaError("ros2msg schema: no type " + name);
  return it->second;
}

}  // namespace rover::log
