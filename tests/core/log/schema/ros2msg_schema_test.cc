#include "core/log/schema/ros2msg_schema.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace rover::log {
namespace {

using ::testing::HasSubstr;

constexpr std::string_view kSeparator =
    "================================================================================\n";

std::string StatusSchema() {
  return std::string(
             "# a comment line\n"
             "byte OK=0\n"
             "byte WARN = 1  # constants carry no data\n"
             "byte level\n"
             "string name\n"
             "KeyValue[] values\n"
             "float64[9] covariance\n"
             "int32[<=4] bounded\n"
             "string<=8 short_name \"a#b\"\n") +
         std::string(kSeparator) + "MSG: diagnostic_msgs/KeyValue\nstring key\nstring value\n";
}

TEST(Ros2MsgSchemaTest, ParsesFieldsArraysAndDependencies) {
  const Ros2MsgSchema schema =
      Ros2MsgSchema::Parse("diagnostic_msgs/msg/DiagnosticStatus", StatusSchema());
  const MessageDefinition& root = schema.root();
  EXPECT_EQ(root.name, "diagnostic_msgs/msg/DiagnosticStatus");
  ASSERT_EQ(root.fields.size(), 6u);
  EXPECT_EQ(root.fields[0].name, "level");
  EXPECT_EQ(root.fields[0].kind, FieldKind::kByte);
  EXPECT_EQ(root.fields[1].kind, FieldKind::kString);
  EXPECT_EQ(root.fields[2].kind, FieldKind::kMessage);
  EXPECT_EQ(root.fields[2].type_name, "diagnostic_msgs/msg/KeyValue");  // same package
  EXPECT_EQ(root.fields[2].array, ArrayKind::kUnbounded);
  EXPECT_EQ(root.fields[3].array, ArrayKind::kFixed);
  EXPECT_EQ(root.fields[3].array_size, 9u);
  EXPECT_EQ(root.fields[4].array, ArrayKind::kBounded);
  EXPECT_EQ(root.fields[4].array_size, 4u);
  EXPECT_EQ(root.fields[5].kind, FieldKind::kString);
  EXPECT_EQ(root.fields[5].name, "short_name");
  EXPECT_EQ(schema.Type("diagnostic_msgs/msg/KeyValue").fields.size(), 2u);
}

TEST(Ros2MsgSchemaTest, BuiltinTimeIsImplicit) {
  const Ros2MsgSchema schema =
      Ros2MsgSchema::Parse("std_msgs/Header", "builtin_interfaces/Time stamp\nstring frame_id\n");
  const MessageDefinition& time = schema.Type("builtin_interfaces/msg/Time");
  ASSERT_EQ(time.fields.size(), 2u);
  EXPECT_EQ(time.fields[0].kind, FieldKind::kInt32);
  EXPECT_EQ(time.fields[1].kind, FieldKind::kUint32);
}

TEST(Ros2MsgSchemaTest, UndefinedTypeIsAnErrorNamingField) {
  try {
    Ros2MsgSchema::Parse("pkg/msg/A", "pkg/B inner\n");
    FAIL() << "expected SchemaError";
  } catch (const SchemaError& e) {
    EXPECT_THAT(e.what(), HasSubstr("'inner'"));
    EXPECT_THAT(e.what(), HasSubstr("pkg/msg/B"));
  }
}

TEST(Ros2MsgSchemaTest, MalformedLinesNameTypeAndLine) {
  try {
    Ros2MsgSchema::Parse("pkg/msg/A", "int32 a\nfloat64[x] b\n");
    FAIL() << "expected SchemaError";
  } catch (const SchemaError& e) {
    EXPECT_THAT(e.what(), HasSubstr("pkg/msg/A"));
    EXPECT_THAT(e.what(), HasSubstr("line 2"));
  }
  EXPECT_THROW(Ros2MsgSchema::Parse("pkg/msg/A", "int32\n"), SchemaError);
  const std::string missing_msg_line = "int32 a\n" + std::string(kSeparator) + "int32 b\n";
  EXPECT_THROW(Ros2MsgSchema::Parse("pkg/msg/A", missing_msg_line), SchemaError);
}

TEST(Ros2MsgSchemaTest, RecursionIsRejected) {
  const std::string text = "pkg/B b\n" + std::string(kSeparator) + "MSG: pkg/B\npkg/A a\n";
  EXPECT_THROW(Ros2MsgSchema::Parse("pkg/msg/A", text), SchemaError);
}

TEST(Ros2MsgSchemaTest, NormalizesTypeNames) {
  EXPECT_EQ(NormalizeTypeName("sensor_msgs/Imu"), "sensor_msgs/msg/Imu");
  EXPECT_EQ(NormalizeTypeName("sensor_msgs/msg/Imu"), "sensor_msgs/msg/Imu");
  EXPECT_EQ(PrimitiveSize(FieldKind::kFloat64), 8u);
  EXPECT_EQ(PrimitiveSize(FieldKind::kString), 0u);
}

}  // namespace
}  // namespace rover::log
