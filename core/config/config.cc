#include "core/config/config.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <system_error>

namespace rover {

// State shared by every ConfigNode of one document. Tracking is keyed by the
// path of the map (not by node identity) so that any number of ConfigNode
// copies or repeated Child() calls for the same map agree.
struct ConfigNode::Document {
  struct MapUse {
    std::set<std::string, std::less<>> used;     // Keys that were read.
    std::set<std::string, std::less<>> queried;  // Keys asked for, present or not.
  };

  std::string source_name;
  std::map<std::string, MapUse, std::less<>> uses;
};

namespace {

std::string KeyPath(std::string_view parent, std::string_view key) {
  std::string path(parent);
  if (!path.empty()) path += '.';
  path += key;
  return path;
}

std::string ItemPath(std::string_view parent, std::size_t index) {
  return std::string(parent) + "[" + std::to_string(index) + "]";
}

std::string Prefix(const std::string& source, int line, std::string_view path) {
  std::string out = source;
  if (line >= 0) out += ":" + std::to_string(line + 1);
  out += ": ";
  if (!path.empty()) {
    out += path;
    out += ": ";
  }
  return out;
}

// yaml-cpp tags non-plain (quoted or block) scalars with "!"; plain ones with
// "?". Only plain scalars may be numbers or booleans, as in the YAML core
// schema, so that "5" in quotes stays a string.
bool IsPlainScalar(const YAML::Node& node) { return node.IsScalar() && node.Tag() != "!"; }

// How a value is shown after "found" in error messages.
std::string Describe(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Null:
      return "null";
    case YAML::NodeType::Sequence:
      return "a list";
    case YAML::NodeType::Map:
      return "a map";
    case YAML::NodeType::Scalar:
      break;
    case YAML::NodeType::Undefined:
      return "nothing";
  }
  constexpr std::size_t kMaxChars = 60;
  std::string text = node.Scalar();
  if (text.size() > kMaxChars) text = text.substr(0, kMaxChars) + "...";
  return IsPlainScalar(node) ? text : "\"" + text + "\"";
}

// Levenshtein distance, for "did you mean" hints on unknown keys.
std::size_t EditDistance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t substitution = diagonal + (a[i - 1] == b[j - 1] ? 0 : 1);
      diagonal = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, substitution});
    }
  }
  return row[b.size()];
}

// Parses a YAML core-schema integer: optional sign, then decimal digits or
// 0x-prefixed hex digits. Returns false if `text` is not such a literal;
// `overflow` is set if it is one but does not fit 64 bits.
bool ParseIntegerLiteral(std::string_view text, bool& negative, uint64_t& magnitude,
                         bool& overflow) {
  negative = false;
  overflow = false;
  if (!text.empty() && (text.front() == '-' || text.front() == '+')) {
    negative = text.front() == '-';
    text.remove_prefix(1);
  }
  int base = 10;
  if (text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) {
    base = 16;
    text.remove_prefix(2);
  }
  if (text.empty()) return false;
  const auto [end, error] =
      std::from_chars(text.data(), text.data() + text.size(), magnitude, base);
  if (end != text.data() + text.size()) return false;
  if (error == std::errc::result_out_of_range) {
    overflow = true;
    return true;
  }
  return error == std::errc();
}

enum class DoubleParse { kOk, kNotANumber, kOutOfRange };

// Parses a YAML core-schema float (also accepting integers): decimal or
// exponent notation, .inf/-.inf/.nan in any of the three spellings.
DoubleParse ParseDoubleLiteral(std::string_view text, double& value) {
  std::string_view body = text;
  double sign = 1.0;
  if (!body.empty() && (body.front() == '-' || body.front() == '+')) {
    sign = body.front() == '-' ? -1.0 : 1.0;
    body.remove_prefix(1);
  }
  if (body == ".inf" || body == ".Inf" || body == ".INF") {
    value = sign * std::numeric_limits<double>::infinity();
    return DoubleParse::kOk;
  }
  if (text == ".nan" || text == ".NaN" || text == ".NAN") {
    value = std::numeric_limits<double>::quiet_NaN();
    return DoubleParse::kOk;
  }
  // from_chars would also accept "inf", "nan" and "infinity", which YAML
  // treats as strings.
  if (body.empty() ||
      !(std::isdigit(static_cast<unsigned char>(body.front())) || body.front() == '.')) {
    return DoubleParse::kNotANumber;
  }
  double magnitude = 0.0;
  const auto [end, error] = std::from_chars(body.data(), body.data() + body.size(), magnitude);
  if (end != body.data() + body.size()) return DoubleParse::kNotANumber;
  if (error == std::errc::result_out_of_range) return DoubleParse::kOutOfRange;
  if (error != std::errc()) return DoubleParse::kNotANumber;
  value = sign * magnitude;
  return DoubleParse::kOk;
}

// Load-time structural checks that yaml-cpp does not do: map keys must be
// plain strings and unique (yaml-cpp silently keeps the first duplicate, which
// would make an edit further down the file ineffective).
void CheckStructure(const YAML::Node& node, const std::string& path, const std::string& source) {
  if (node.IsMap()) {
    std::map<std::string, int, std::less<>> first_line;
    for (const auto& entry : node) {
      const YAML::Node& key = entry.first;
      const int line = key.Mark().line;
      if (!key.IsScalar()) {
        throw ConfigError(Prefix(source, line, path) + "map keys must be strings, found " +
                          Describe(key));
      }
      const auto [it, inserted] = first_line.emplace(key.Scalar(), line);
      if (!inserted) {
        throw ConfigError(Prefix(source, line, KeyPath(path, key.Scalar())) +
                          "duplicate key (first defined at line " + std::to_string(it->second + 1) +
                          ")");
      }
      CheckStructure(entry.second, KeyPath(path, key.Scalar()), source);
    }
  } else if (node.IsSequence()) {
    for (std::size_t i = 0; i < node.size(); ++i) {
      CheckStructure(node[i], ItemPath(path, i), source);
    }
  }
}

}  // namespace

// ------------------------------------------------------------------ loading

ConfigNode::ConfigNode(std::shared_ptr<Document> doc, YAML::Node node, std::string path, int line)
    : doc_(std::move(doc)), node_(std::move(node)), path_(std::move(path)), line_(line) {}

ConfigNode ConfigNode::LoadFile(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw ConfigError(path + ": cannot open file");
  std::ostringstream contents;
  contents << file.rdbuf();
  if (file.bad()) throw ConfigError(path + ": read error");
  return LoadString(contents.str(), path);
}

ConfigNode ConfigNode::LoadString(std::string_view yaml, std::string source_name) {
  YAML::Node root;
  try {
    root = YAML::Load(std::string(yaml));
  } catch (const YAML::ParserException& e) {
    throw ConfigError(Prefix(source_name, e.mark.line, "") + "YAML syntax error at column " +
                      std::to_string(e.mark.column + 1) + ": " + e.msg);
  } catch (const YAML::Exception& e) {
    throw ConfigError(Prefix(source_name, e.mark.line, "") + "cannot parse YAML: " + e.msg);
  }
  int line = -1;
  if (root.IsNull()) {
    // An empty (or all-comment) document: every option takes its default.
    root = YAML::Node(YAML::NodeType::Map);
  } else if (root.IsScalar()) {
    throw ConfigError(Prefix(source_name, root.Mark().line, "") +
                      "expected a map at the top level, found " + Describe(root));
  } else {
    line = root.Mark().line;
  }
  CheckStructure(root, "", source_name);
  auto doc = std::make_shared<Document>();
  doc->source_name = std::move(source_name);
  return ConfigNode(std::move(doc), std::move(root), "", line);
}

// ------------------------------------------------------------------- lookup

std::optional<ConfigNode::Located> ConfigNode::Find(std::string_view key) const {
  if (!node_.IsMap()) {
    Throw(Located{node_, path_, line_}, "expected a map, found " + Describe(node_));
  }
  Document::MapUse& use = doc_->uses[path_];
  use.queried.emplace(key);
  for (const auto& entry : node_) {
    if (entry.first.Scalar() == key) {
      use.used.emplace(key);
      return Located{entry.second, KeyPath(path_, key), entry.first.Mark().line};
    }
  }
  return std::nullopt;
}

ConfigNode::Located ConfigNode::Require(std::string_view key) const {
  std::optional<Located> value = Find(key);
  if (!value) Throw(Located{node_, KeyPath(path_, key), line_}, "missing required key");
  return *std::move(value);
}

bool ConfigNode::Has(std::string_view key) const { return Find(key).has_value(); }

ConfigNode ConfigNode::MakeChild(const Located& value) const {
  if (!value.node.IsMap()) {
    Throw(value, "expected a map, found " + Describe(value.node) +
                     (value.node.IsNull() ? " (write {} for an empty map)" : ""));
  }
  return ConfigNode(doc_, value.node, value.path, value.line);
}

ConfigNode ConfigNode::Child(std::string_view key) const { return MakeChild(Require(key)); }

std::vector<ConfigNode> ConfigNode::MakeItems(const Located& list) const {
  std::vector<ConfigNode> items;
  for (const Located& element : ToElements(list)) {
    items.push_back(ConfigNode(doc_, element.node, element.path, element.line));
  }
  return items;
}

std::vector<ConfigNode> ConfigNode::ChildList(std::string_view key) const {
  return MakeItems(Require(key));
}

std::vector<ConfigNode> ConfigNode::Items() const {
  return MakeItems(Located{node_, path_, line_});
}

std::vector<std::string> ConfigNode::Keys() const {
  if (!node_.IsMap()) {
    Throw(Located{node_, path_, line_}, "expected a map, found " + Describe(node_));
  }
  std::vector<std::string> keys;
  for (const auto& entry : node_) keys.push_back(entry.first.Scalar());
  return keys;
}

double ConfigNode::GetAllowNonFinite(std::string_view key) const {
  return ToDouble(Require(key), /*allow_non_finite=*/true);
}

double ConfigNode::GetAllowNonFinite(std::string_view key, double default_value) const {
  const std::optional<Located> value = Find(key);
  return value ? ToDouble(*value, /*allow_non_finite=*/true) : default_value;
}

// --------------------------------------------------------------- conversion

bool ConfigNode::ToBool(const Located& value) const {
  // Only the YAML 1.2 spellings: YAML 1.1's yes/no/on/off are a classic
  // source of surprises (a country code "NO" becoming false).
  if (IsPlainScalar(value.node)) {
    const std::string& text = value.node.Scalar();
    if (text == "true" || text == "True" || text == "TRUE") return true;
    if (text == "false" || text == "False" || text == "FALSE") return false;
  }
  Throw(value, "expected a boolean (true or false), found " + Describe(value.node));
}

int64_t ConfigNode::ToInt(const Located& value, int64_t lo, int64_t hi) const {
  const uint64_t magnitude_limit = uint64_t{1} << 63;
  bool negative = false;
  uint64_t magnitude = 0;
  bool overflow = false;
  if (IsPlainScalar(value.node) &&
      ParseIntegerLiteral(value.node.Scalar(), negative, magnitude, overflow)) {
    if (!overflow && negative && magnitude <= magnitude_limit) {
      // -magnitude computed in unsigned arithmetic is exact modulo 2^64, and
      // the cast back is well defined in C++20.
      const int64_t v = static_cast<int64_t>(0 - magnitude);
      if (v >= lo && v <= hi) return v;
    } else if (!overflow && !negative && magnitude < magnitude_limit) {
      const int64_t v = static_cast<int64_t>(magnitude);
      if (v >= lo && v <= hi) return v;
    }
    ThrowRange(value, true, NumberText(lo), NumberText(hi));
  }
  // Accept integral values written as floats ("1e3", "2.0"), but only while
  // doubles represent every integer exactly.
  double d = 0.0;
  if (IsPlainScalar(value.node) && ParseDoubleLiteral(value.node.Scalar(), d) == DoubleParse::kOk &&
      std::isfinite(d) && std::trunc(d) == d) {
    constexpr double kExactLimit = 9007199254740992.0;  // 2^53
    if (std::abs(d) <= kExactLimit && d >= static_cast<double>(lo) &&
        d <= static_cast<double>(hi)) {
      return static_cast<int64_t>(d);
    }
    ThrowRange(value, true, NumberText(lo), NumberText(hi));
  }
  Throw(value, "expected an integer, found " + Describe(value.node));
}

uint64_t ConfigNode::ToUint(const Located& value, uint64_t hi) const {
  bool negative = false;
  uint64_t magnitude = 0;
  bool overflow = false;
  if (IsPlainScalar(value.node) &&
      ParseIntegerLiteral(value.node.Scalar(), negative, magnitude, overflow)) {
    if (!overflow && (!negative || magnitude == 0) && magnitude <= hi) return magnitude;
    ThrowRange(value, true, "0", NumberText(hi));
  }
  double d = 0.0;
  if (IsPlainScalar(value.node) && ParseDoubleLiteral(value.node.Scalar(), d) == DoubleParse::kOk &&
      std::isfinite(d) && std::trunc(d) == d) {
    constexpr double kExactLimit = 9007199254740992.0;  // 2^53
    if (d >= 0.0 && d <= kExactLimit && d <= static_cast<double>(hi)) {
      return static_cast<uint64_t>(d);
    }
    ThrowRange(value, true, "0", NumberText(hi));
  }
  Throw(value, "expected an integer, found " + Describe(value.node));
}

double ConfigNode::ToDouble(const Located& value, bool allow_non_finite) const {
  double d = 0.0;
  const DoubleParse result = IsPlainScalar(value.node) ? ParseDoubleLiteral(value.node.Scalar(), d)
                                                       : DoubleParse::kNotANumber;
  if (result == DoubleParse::kOutOfRange) {
    Throw(value, "number out of range for double, found " + Describe(value.node));
  }
  if (result != DoubleParse::kOk) {
    Throw(value, "expected a number, found " + Describe(value.node));
  }
  if (!allow_non_finite && !std::isfinite(d)) {
    Throw(value, "expected a finite number, found " + Describe(value.node));
  }
  return d;
}

float ConfigNode::ToFloat(const Located& value) const {
  const double d = ToDouble(value, /*allow_non_finite=*/false);
  if (std::abs(d) > static_cast<double>(std::numeric_limits<float>::max())) {
    Throw(value, "number out of range for float, found " + Describe(value.node));
  }
  return static_cast<float>(d);
}

std::string ConfigNode::ToString(const Located& value) const {
  if (!value.node.IsScalar()) {
    Throw(value, "expected a string, found " + Describe(value.node));
  }
  return value.node.Scalar();
}

std::string ConfigNode::EnumText(const Located& value) const {
  if (!value.node.IsScalar()) {
    Throw(value, "expected a name, found " + Describe(value.node));
  }
  return value.node.Scalar();
}

std::vector<ConfigNode::Located> ConfigNode::ToElements(const Located& value) const {
  if (!value.node.IsSequence()) {
    Throw(value, "expected a list, found " + Describe(value.node));
  }
  std::vector<Located> elements;
  elements.reserve(value.node.size());
  for (std::size_t i = 0; i < value.node.size(); ++i) {
    const YAML::Node element = value.node[i];
    // A null element has no position of its own (yaml-cpp reports where the
    // next token starts); fall back to the list's line.
    const int line = element.IsNull() ? value.line : element.Mark().line;
    elements.push_back(Located{element, ItemPath(value.path, i), line});
  }
  return elements;
}

// ------------------------------------------------------------------- errors

void ConfigNode::Throw(const Located& at, std::string_view message) const {
  throw ConfigError(Prefix(doc_->source_name, at.line, at.path) + std::string(message));
}

void ConfigNode::ThrowRange(const Located& at, bool integer, const std::string& lo,
                            const std::string& hi) const {
  Throw(at, std::string(integer ? "expected an integer" : "expected a number") + " in [" + lo +
                ", " + hi + "], found " + Describe(at.node));
}

void ConfigNode::ThrowEnum(const Located& at, const std::vector<std::string_view>& names) const {
  std::string allowed;
  for (const std::string_view name : names) {
    if (!allowed.empty()) allowed += ", ";
    allowed += "\"" + std::string(name) + "\"";
  }
  Throw(at, "expected one of " + allowed + ", found " + Describe(at.node));
}

void ConfigNode::ThrowShape(const Located& at, int rows, int cols, std::size_t found) const {
  const std::string found_text = "found a list of " + std::to_string(found) + " elements";
  if (rows == 1 || cols == 1) {
    Throw(at, "expected a list of " + std::to_string(rows * cols) + " numbers, " + found_text);
  }
  Throw(at, "expected a " + std::to_string(rows) + "x" + std::to_string(cols) +
                " matrix, as a list of " + std::to_string(rows) + " rows of " +
                std::to_string(cols) + " numbers or a flat row-major list of " +
                std::to_string(rows * cols) + " numbers, " + found_text);
}

void ConfigNode::Fail(std::string_view key, std::string_view message) const {
  if (!key.empty() && node_.IsMap()) {
    for (const auto& entry : node_) {
      if (entry.first.Scalar() == key) {
        Throw(Located{entry.second, KeyPath(path_, key), entry.first.Mark().line}, message);
      }
    }
    Throw(Located{node_, KeyPath(path_, key), line_}, message);
  }
  Throw(Located{node_, path_, line_}, message);
}

std::string ConfigNode::Where() const {
  std::string out = doc_->source_name;
  if (line_ >= 0) out += ":" + std::to_string(line_ + 1);
  if (!path_.empty()) out += ": " + path_;
  return out;
}

std::string ConfigNode::NumberText(int64_t v) { return std::to_string(v); }
std::string ConfigNode::NumberText(uint64_t v) { return std::to_string(v); }

std::string ConfigNode::NumberText(double v) {
  // Shortest text that reads back as v: "0.1", not "0.100000".
  std::array<char, 32> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), v);
  return std::string(buffer.data(), result.ptr);
}

std::string ConfigNode::NumberText(float v) {
  std::array<char, 32> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), v);
  return std::string(buffer.data(), result.ptr);
}

// ------------------------------------------------------------ unknown keys

void ConfigNode::CollectUnknownKeys(const Document& doc, const YAML::Node& node,
                                    const std::string& path, bool recursive,
                                    std::vector<std::pair<int, std::string>>& out) {
  if (node.IsSequence()) {
    if (!recursive) return;
    for (std::size_t i = 0; i < node.size(); ++i) {
      CollectUnknownKeys(doc, node[i], ItemPath(path, i), recursive, out);
    }
    return;
  }
  if (!node.IsMap()) return;
  static const Document::MapUse kNothingUsed;
  const auto it = doc.uses.find(path);
  const Document::MapUse& use = it == doc.uses.end() ? kNothingUsed : it->second;
  std::set<std::string, std::less<>> present;
  for (const auto& entry : node) present.insert(entry.first.Scalar());

  for (const auto& entry : node) {
    const std::string& key = entry.first.Scalar();
    const int line = entry.first.Mark().line;
    if (use.used.contains(key)) {
      if (recursive) CollectUnknownKeys(doc, entry.second, KeyPath(path, key), recursive, out);
      continue;
    }
    std::string text = Prefix(doc.source_name, line, KeyPath(path, key)) + "unknown key";
    // Suggest the closest key the loader asked for but did not find: that is
    // the optional key this one is most likely a misspelling of, and the case
    // this check exists for (the option silently kept its default).
    std::size_t best_distance = std::max<std::size_t>(2, key.size() / 4) + 1;
    std::string best;
    for (const std::string& candidate : use.queried) {
      if (present.contains(candidate)) continue;
      const std::size_t distance = EditDistance(key, candidate);
      if (distance < best_distance) {
        best_distance = distance;
        best = candidate;
      }
    }
    if (!best.empty()) text += " (did you mean \"" + best + "\"?)";
    out.emplace_back(line, std::move(text));
  }
}

void ConfigNode::CheckUnknownKeys(bool recursive) const {
  std::vector<std::pair<int, std::string>> unknown;
  CollectUnknownKeys(*doc_, node_, path_, recursive, unknown);
  if (unknown.empty()) return;
  // One line per key, in file order, each with its own location so editors
  // and CI logs can jump to it.
  std::stable_sort(unknown.begin(), unknown.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::string message;
  for (const auto& [line, text] : unknown) {
    if (!message.empty()) message += '\n';
    message += text;
  }
  throw ConfigError(message);
}

void ConfigNode::CheckNoUnknownKeys() const { CheckUnknownKeys(/*recursive=*/false); }

void ConfigNode::CheckNoUnknownKeysRecursive() const { CheckUnknownKeys(/*recursive=*/true); }

}  // namespace rover
