// ros2msg schema texts: format, dependency closure, and agreement with the
// bytes Serialize writes, checked by the schema-driven DynamicDecoder (the
// way a generic reader such as Foxglove decodes them; the npm conformance
// test repeats this with Foxglove's own decoder).

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
#include "core/log/schema/dynamic_decoder.h"
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

// The transitive closure of `type`'s message-typed fields, as "pkg/Type".
void Closure(const Ros2MsgSchema& schema, const std::string& type, std::set<std::string>* out) {
  for (const FieldDefinition& field : schema.Type(type).fields) {
    if (field.kind != FieldKind::kMessage) continue;
    if (out->insert(ShortName(field.type_name)).second) Closure(schema, field.type_name, out);
  }
}

std::string ValueAt(const std::vector<FlatField>& fields, const std::string& path) {
  for (const FlatField& f : fields) {
    if (f.path == path) return FormatValue(f);
  }
  return "<missing " + path + ">";
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
    const Ros2MsgSchema schema = Ros2MsgSchema::Parse(entry.name, text);
    std::set<std::string> closure;
    Closure(schema, schema.root().name, &closure);
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
  std::set<std::string> names;
  for (const Section& section :
       SplitSchema("nav_msgs/msg/Odometry", MessageTraits<nav_msgs::Odometry>::Definition())) {
    names.insert(section.name);
  }
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
  EXPECT_EQ(names.size(), 38u);
  EXPECT_TRUE(names.contains("rover_msgs/msg/LogHealth"));
  EXPECT_TRUE(names.contains("rover_msgs/msg/TeamMessage"));
}

template <typename T>
class SchemaAgreementTest : public ::testing::Test {};
TYPED_TEST_SUITE(SchemaAgreementTest, cdr_test::AllMessageTypes, cdr_test::MessageTypeName);

// Decoding our bytes by walking our schema text must consume every byte:
// field order, types and array shapes in the text match what Serialize writes.
TYPED_TEST(SchemaAgreementTest, SchemaDrivenDecoderConsumesExactlyTheMessage) {
  using T = TypeParam;
  const Ros2MsgSchema schema =
      Ros2MsgSchema::Parse(MessageTraits<T>::kName, MessageTraits<T>::Definition());
  const DynamicDecoder decoder(schema, {.max_byte_array_elements = 1 << 20});
  for (uint64_t seed = 1; seed <= 10; ++seed) {
    cdr_test::RandomMessages random(seed);
    const std::vector<std::byte> bytes = SerializeMessage(random.template Make<T>());
    std::vector<FlatField> fields;
    std::string error;
    std::size_t consumed = 0;
    ASSERT_TRUE(decoder.Decode(bytes, &fields, &error, &consumed))
        << "seed " << seed << ": " << error;
    EXPECT_EQ(consumed, bytes.size()) << "seed " << seed;
  }
}

TEST(SchemaValuesTest, SchemaDrivenDecoderSeesOurValues) {
  cdr_test::RandomMessages random(21);
  const sensor_msgs::Imu imu = random.Make<sensor_msgs::Imu>();
  const Ros2MsgSchema schema =
      Ros2MsgSchema::Parse("sensor_msgs/msg/Imu", MessageTraits<sensor_msgs::Imu>::Definition());
  std::vector<FlatField> v;
  std::string error;
  ASSERT_TRUE(DynamicDecoder(schema).Decode(SerializeMessage(imu), &v, &error)) << error;
  auto f64 = [](double d) {
    char text[64];
    std::snprintf(text, sizeof text, "%.17g", d);
    return std::string(text);
  };
  EXPECT_EQ(ValueAt(v, "header.stamp.sec"), std::to_string(imu.header.stamp.sec));
  EXPECT_EQ(ValueAt(v, "header.stamp.nanosec"), std::to_string(imu.header.stamp.nanosec));
  EXPECT_EQ(ValueAt(v, "header.frame_id"), imu.header.frame_id.view());
  EXPECT_EQ(ValueAt(v, "orientation.w"), f64(imu.orientation.w));
  EXPECT_EQ(ValueAt(v, "angular_velocity_covariance[4]"), f64(imu.angular_velocity_covariance[4]));
  EXPECT_EQ(ValueAt(v, "linear_acceleration.z"), f64(imu.linear_acceleration.z));

  diagnostic_msgs::DiagnosticArray array;
  array.status.resize(2);
  array.status[1].level = diagnostic_msgs::DiagnosticStatus::kStale;
  array.status[1].values = {{"temp", "41C"}};
  const Ros2MsgSchema diag_schema =
      Ros2MsgSchema::Parse("diagnostic_msgs/msg/DiagnosticArray",
                           MessageTraits<diagnostic_msgs::DiagnosticArray>::Definition());
  ASSERT_TRUE(DynamicDecoder(diag_schema).Decode(SerializeMessage(array), &v, &error)) << error;
  EXPECT_EQ(ValueAt(v, "status[1].level"), "3");
  EXPECT_EQ(ValueAt(v, "status[1].values[0].value"), "41C");
}

}  // namespace
}  // namespace rover::log
