// ros2msg schema texts: format, dependency closure, and agreement with the
// bytes Serialize writes (checked by an independent schema-driven decoder
// written here, the way a generic reader such as Foxglove's decodes them).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "core/log/msgs/all_msgs.h"
#include "tests/core/log/cdr/random_msgs.h"

namespace rover::log {
namespace {

using ::testing::HasSubstr;
using ::testing::UnorderedElementsAreArray;

const std::string kSeparator = "\n" + std::string(80, '=') + "\n";

// "pkg/msg/Type" -> "pkg/Type".
std::string ShortName(std::string_view name) {
  const size_t first = name.find('/');
  const size_t last = name.rfind('/');
  return std::string(name.substr(0, first)) + std::string(name.substr(last));
}

struct Section {
  std::string name;  // "pkg/Type"
  std::string text;
};

// Splits a schema into the top-level section and its "MSG:" sections.
std::vector<Section> SplitSchema(std::string_view root, std::string_view text) {
  std::vector<Section> sections;
  std::string rest(text);
  std::string name = ShortName(root);
  while (true) {
    const size_t sep = rest.find(kSeparator);
    sections.push_back({name, rest.substr(0, sep)});
    if (sep == std::string::npos) break;
    rest = rest.substr(sep + kSeparator.size());
    const size_t newline = rest.find('\n');
    const std::string header = rest.substr(0, newline);
    EXPECT_EQ(header.rfind("MSG: ", 0), 0u) << header;
    name = header.substr(5);
    rest = newline == std::string::npos ? "" : rest.substr(newline + 1);
  }
  return sections;
}

struct Field {
  std::string type;  // Primitive name or "pkg/Type".
  std::string name;
  int array = 0;  // 0: scalar, -1: unbounded sequence, N: fixed array.
};

const std::set<std::string> kPrimitives = {"bool",   "byte",    "char",    "int8",   "uint8",
                                           "int16",  "uint16",  "int32",   "uint32", "int64",
                                           "uint64", "float32", "float64", "string"};

// A deliberately independent little .msg parser: fields only, constants and
// comments skipped, bare type names resolved in the enclosing package.
std::vector<Field> ParseFields(const Section& section) {
  std::vector<Field> fields;
  const std::string package = section.name.substr(0, section.name.find('/'));
  std::istringstream lines(section.text);
  std::string line;
  while (std::getline(lines, line)) {
    line = line.substr(0, line.find('#'));
    std::istringstream tokens(line);
    std::string type;
    std::string name;
    if (!(tokens >> type >> name)) continue;
    if (name.find('=') != std::string::npos) continue;  // Constant.
    Field field;
    field.name = name;
    if (const size_t bracket = type.find('['); bracket != std::string::npos) {
      const std::string size = type.substr(bracket + 1, type.size() - bracket - 2);
      field.array = size.empty() ? -1 : std::stoi(size);
      type = type.substr(0, bracket);
    }
    if (kPrimitives.count(type) == 0 && type.find('/') == std::string::npos) {
      type = package + "/" + type;
    }
    if (type.find("/msg/") != std::string::npos) type = ShortName(type);
    field.type = type;
    fields.push_back(field);
  }
  return fields;
}

using Schema = std::map<std::string, std::vector<Field>>;

Schema ParseSchema(std::string_view root, std::string_view text) {
  Schema schema;
  for (const Section& section : SplitSchema(root, text)) {
    schema[section.name] = ParseFields(section);
  }
  return schema;
}

// Schema-driven CDR decoder producing "path=value" lines.
class GenericDecoder {
 public:
  GenericDecoder(const Schema& schema, std::span<const std::byte> bytes)
      : schema_(schema), bytes_(bytes) {}

  bool Decode(const std::string& type, const std::string& path) {
    const auto it = schema_.find(type);
    if (it == schema_.end()) return Error("no definition for " + type);
    for (const Field& field : it->second) {
      const std::string field_path = path.empty() ? field.name : path + "." + field.name;
      size_t count = 1;
      if (field.array == -1) {
        uint32_t n = 0;
        if (!Read(4, &n)) return false;
        count = n;
      } else if (field.array > 0) {
        count = static_cast<size_t>(field.array);
      }
      for (size_t i = 0; i < count; ++i) {
        const std::string element_path =
            field.array == 0 ? field_path : field_path + "[" + std::to_string(i) + "]";
        if (!DecodeValue(field.type, element_path)) return false;
      }
    }
    return true;
  }

  size_t offset() const { return pos_; }
  const std::map<std::string, std::string>& values() const { return values_; }
  const std::string& error() const { return error_; }

 private:
  bool DecodeValue(const std::string& type, const std::string& path) {
    char text[64];
    if (type == "string") {
      uint32_t length = 0;
      if (!Read(4, &length)) return false;
      if (length > bytes_.size() - pos_ || length == 0) return Error("bad string at " + path);
      values_[path] = std::string(reinterpret_cast<const char*>(bytes_.data() + pos_), length - 1);
      pos_ += length;
      return true;
    }
    if (type == "float64") {
      double v = 0;
      if (!Read(8, &v)) return false;
      std::snprintf(text, sizeof text, "%.17g", v);
    } else if (type == "int32") {
      int32_t v = 0;
      if (!Read(4, &v)) return false;
      std::snprintf(text, sizeof text, "%" PRId32, v);
    } else if (type == "uint32") {
      uint32_t v = 0;
      if (!Read(4, &v)) return false;
      std::snprintf(text, sizeof text, "%" PRIu32, v);
    } else if (type == "uint64") {
      uint64_t v = 0;
      if (!Read(8, &v)) return false;
      std::snprintf(text, sizeof text, "%" PRIu64, v);
    } else if (type == "uint8" || type == "byte") {
      uint8_t v = 0;
      if (!Read(1, &v)) return false;
      std::snprintf(text, sizeof text, "%u", static_cast<unsigned>(v));
    } else if (kPrimitives.count(type) != 0) {
      return Error("primitive not handled by the test decoder: " + type);
    } else {
      return Decode(type, path);
    }
    values_[path] = text;
    return true;
  }

  template <typename T>
  bool Read(size_t size, T* out) {
    // Alignment relative to the payload, which starts after the 4-byte header.
    while ((pos_ - 4) % size != 0) ++pos_;
    if (pos_ + size > bytes_.size()) return Error("truncated");
    std::memcpy(out, bytes_.data() + pos_, size);
    pos_ += size;
    return true;
  }

  bool Error(const std::string& what) {
    if (error_.empty()) error_ = what;
    return false;
  }

  const Schema& schema_;
  std::span<const std::byte> bytes_;
  size_t pos_ = 4;
  std::map<std::string, std::string> values_;
  std::string error_;
};

// The transitive closure of `type`'s complex dependencies.
void Closure(const Schema& schema, const std::string& type, std::set<std::string>* out) {
  const auto it = schema.find(type);
  if (it == schema.end()) return;
  for (const Field& field : it->second) {
    if (kPrimitives.count(field.type) != 0) continue;
    if (out->insert(field.type).second) Closure(schema, field.type, out);
  }
}

TEST(SchemaTest, EveryDependencyAppearsExactlyOnce) {
  for (const MessageSchema& entry : AllMessageSchemas()) {
    SCOPED_TRACE(entry.name);
    const std::string_view text = entry.definition();
    const std::vector<Section> sections = SplitSchema(entry.name, text);
    std::vector<std::string> names;
    for (const Section& section : sections) names.push_back(section.name);
    // No type is listed twice (and the root is never repeated as a MSG).
    const std::set<std::string> unique(names.begin(), names.end());
    EXPECT_EQ(unique.size(), names.size());
    // Exactly the types the fields reference, transitively.
    const Schema schema = ParseSchema(entry.name, text);
    std::set<std::string> closure;
    Closure(schema, ShortName(entry.name), &closure);
    EXPECT_THAT(std::vector<std::string>(names.begin() + 1, names.end()),
                UnorderedElementsAreArray(closure));
    // No section is empty, and no other '=' line sneaks in.
    for (const Section& section : sections) EXPECT_FALSE(section.text.empty()) << section.name;
    EXPECT_EQ(std::string(text).find("=\n="), std::string::npos);
  }
}

TEST(SchemaTest, HeaderSchemaText) {
  EXPECT_EQ(MessageTraits<std_msgs::Header>::Definition(),
            "builtin_interfaces/Time stamp\n"
            "string frame_id\n" +
                std::string(80, '=') +
                "\n"
                "MSG: builtin_interfaces/Time\n"
                "int32 sec\n"
                "uint32 nanosec");
}

TEST(SchemaTest, TimeHasNoDependencies) {
  EXPECT_EQ(MessageTraits<builtin_interfaces::Time>::Definition(), "int32 sec\nuint32 nanosec");
}

TEST(SchemaTest, ImuSchema) {
  const std::string_view text = MessageTraits<sensor_msgs::Imu>::Definition();
  EXPECT_EQ(text.substr(0, text.find(kSeparator)),
            "std_msgs/Header header\n"
            "geometry_msgs/Quaternion orientation\n"
            "float64[9] orientation_covariance\n"
            "geometry_msgs/Vector3 angular_velocity\n"
            "float64[9] angular_velocity_covariance\n"
            "geometry_msgs/Vector3 linear_acceleration\n"
            "float64[9] linear_acceleration_covariance");
  std::vector<std::string> names;
  for (const Section& section : SplitSchema("sensor_msgs/msg/Imu", text)) {
    names.push_back(section.name);
  }
  EXPECT_THAT(
      names, ::testing::ElementsAre("sensor_msgs/Imu", "std_msgs/Header", "builtin_interfaces/Time",
                                    "geometry_msgs/Quaternion", "geometry_msgs/Vector3"));
}

TEST(SchemaTest, OdometryIncludesNestedGeometry) {
  const Schema schema =
      ParseSchema("nav_msgs/msg/Odometry", MessageTraits<nav_msgs::Odometry>::Definition());
  std::set<std::string> names;
  for (const auto& [name, fields] : schema) names.insert(name);
  EXPECT_EQ(names,
            (std::set<std::string>{"nav_msgs/Odometry", "std_msgs/Header",
                                   "builtin_interfaces/Time", "geometry_msgs/PoseWithCovariance",
                                   "geometry_msgs/Pose", "geometry_msgs/Point",
                                   "geometry_msgs/Quaternion", "geometry_msgs/TwistWithCovariance",
                                   "geometry_msgs/Twist", "geometry_msgs/Vector3"}));
}

TEST(SchemaTest, DiagnosticStatusHasLevelConstants) {
  const std::string_view text = MessageTraits<diagnostic_msgs::DiagnosticArray>::Definition();
  EXPECT_THAT(std::string(text), HasSubstr("MSG: diagnostic_msgs/DiagnosticStatus\n"
                                           "byte OK=0\n"
                                           "byte WARN=1\n"
                                           "byte ERROR=2\n"
                                           "byte STALE=3\n"
                                           "byte level\n"));
  EXPECT_THAT(std::string(text), HasSubstr("MSG: diagnostic_msgs/KeyValue\n"
                                           "string key\n"
                                           "string value"));
}

TEST(SchemaTest, QuaternionKeepsRosDefaults) {
  EXPECT_EQ(MessageTraits<geometry_msgs::Quaternion>::Definition(),
            "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1");
}

TEST(SchemaTest, DefinitionIsCached) {
  const std::string_view a = MessageTraits<tf2_msgs::TFMessage>::Definition();
  const std::string_view b = MessageTraits<tf2_msgs::TFMessage>::Definition();
  EXPECT_EQ(a.data(), b.data());
}

TEST(SchemaTest, RegistryListsEveryTypeOnce) {
  std::set<std::string_view> names;
  for (const MessageSchema& entry : AllMessageSchemas()) names.insert(entry.name);
  EXPECT_EQ(names.size(), AllMessageSchemas().size());
  EXPECT_EQ(names.size(), 21u);
  EXPECT_TRUE(names.contains("rover_msgs/msg/LogHealth"));
}

template <typename T>
class SchemaAgreementTest : public ::testing::Test {};
TYPED_TEST_SUITE(SchemaAgreementTest, cdr_test::AllMessageTypes, cdr_test::MessageTypeName);

// Decoding our bytes by walking our schema text must consume every byte:
// field order, types and array shapes in the text match what Serialize writes.
TYPED_TEST(SchemaAgreementTest, SchemaDrivenDecoderConsumesExactlyTheMessage) {
  using T = TypeParam;
  const Schema schema = ParseSchema(MessageTraits<T>::kName, MessageTraits<T>::Definition());
  for (uint64_t seed = 1; seed <= 10; ++seed) {
    cdr_test::RandomMessages random(seed);
    const std::vector<std::byte> bytes = SerializeMessage(random.template Make<T>());
    GenericDecoder decoder(schema, bytes);
    ASSERT_TRUE(decoder.Decode(ShortName(MessageTraits<T>::kName), ""))
        << "seed " << seed << ": " << decoder.error();
    EXPECT_EQ(decoder.offset(), bytes.size()) << "seed " << seed;
  }
}

TEST(SchemaValuesTest, SchemaDrivenDecoderSeesOurValues) {
  cdr_test::RandomMessages random(21);
  const sensor_msgs::Imu imu = random.Make<sensor_msgs::Imu>();
  const std::vector<std::byte> bytes = SerializeMessage(imu);
  const Schema schema =
      ParseSchema("sensor_msgs/msg/Imu", MessageTraits<sensor_msgs::Imu>::Definition());
  GenericDecoder decoder(schema, bytes);
  ASSERT_TRUE(decoder.Decode("sensor_msgs/Imu", "")) << decoder.error();
  const auto& v = decoder.values();
  auto f64 = [](double d) {
    char text[64];
    std::snprintf(text, sizeof text, "%.17g", d);
    return std::string(text);
  };
  EXPECT_EQ(v.at("header.stamp.sec"), std::to_string(imu.header.stamp.sec));
  EXPECT_EQ(v.at("header.stamp.nanosec"), std::to_string(imu.header.stamp.nanosec));
  EXPECT_EQ(v.at("header.frame_id"), imu.header.frame_id.view());
  EXPECT_EQ(v.at("orientation.w"), f64(imu.orientation.w));
  EXPECT_EQ(v.at("angular_velocity_covariance[4]"), f64(imu.angular_velocity_covariance[4]));
  EXPECT_EQ(v.at("linear_acceleration.z"), f64(imu.linear_acceleration.z));

  diagnostic_msgs::DiagnosticArray array;
  array.status.resize(2);
  array.status[1].level = diagnostic_msgs::DiagnosticStatus::kStale;
  array.status[1].values = {{"temp", "41C"}};
  const std::vector<std::byte> diag_bytes = SerializeMessage(array);
  const Schema diag_schema =
      ParseSchema("diagnostic_msgs/msg/DiagnosticArray",
                  MessageTraits<diagnostic_msgs::DiagnosticArray>::Definition());
  GenericDecoder diag(diag_schema, diag_bytes);
  ASSERT_TRUE(diag.Decode("diagnostic_msgs/DiagnosticArray", "")) << diag.error();
  EXPECT_EQ(diag.values().at("status[1].level"), "3");
  EXPECT_EQ(diag.values().at("status[1].values[0].value"), "41C");
}

}  // namespace
}  // namespace rover::log
