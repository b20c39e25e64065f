#include "core/log/schema/dynamic_decoder.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/log/msgs/all_msgs.h"

namespace rover::log {
namespace {

using ::testing::HasSubstr;

template <typename T>
std::vector<FlatField> DecodeWithOwnSchema(const T& msg) {
  const Ros2MsgSchema schema =
      Ros2MsgSchema::Parse(MessageTraits<T>::kName, MessageTraits<T>::Definition());
  const DynamicDecoder decoder(schema);
  std::vector<FlatField> fields;
  std::string error;
  EXPECT_TRUE(decoder.Decode(SerializeMessage(msg), &fields, &error)) << error;
  return fields;
}

std::string ValueAt(const std::vector<FlatField>& fields, const std::string& path) {
  for (const FlatField& f : fields) {
    if (f.path == path) return FormatValue(f);
  }
  return "<missing " + path + ">";
}

TEST(DynamicDecoderTest, DecodesImuFromItsSchemaText) {
  sensor_msgs::Imu imu;
  imu.header.stamp = {12, 345};
  imu.header.frame_id = "body";
  imu.angular_velocity.z = 0.1;
  imu.linear_acceleration.x = -9.80665;
  imu.orientation_covariance[8] = 2.5e-3;
  const auto fields = DecodeWithOwnSchema(imu);
  // 4 header leaves... quaternion 4 + 9 + 3 + 9 + 3 + 9 = 37, header 3.
  EXPECT_EQ(fields.size(), 40u);
  EXPECT_EQ(ValueAt(fields, "header.stamp.sec"), "12");
  EXPECT_EQ(ValueAt(fields, "header.stamp.nanosec"), "345");
  EXPECT_EQ(ValueAt(fields, "header.frame_id"), "body");
  EXPECT_EQ(ValueAt(fields, "angular_velocity.z"), "0.10000000000000001");
  EXPECT_EQ(ValueAt(fields, "linear_acceleration.x"), "-9.8066499999999994");
  EXPECT_EQ(ValueAt(fields, "orientation_covariance[8]"), "0.0025000000000000001");
}

TEST(DynamicDecoderTest, FlattensNestedSequences) {
  diagnostic_msgs::DiagnosticArray array;
  array.header.frame_id = "roverd";
  array.status.resize(2);
  array.status[1].level = diagnostic_msgs::DiagnosticStatus::kWarn;
  array.status[1].name = "imu";
  array.status[1].values = {{"rate_hz", "399.8"}, {"drops", "3"}};
  const auto fields = DecodeWithOwnSchema(array);
  EXPECT_EQ(ValueAt(fields, "status[1].level"), "1");
  EXPECT_EQ(ValueAt(fields, "status[1].name"), "imu");
  EXPECT_EQ(ValueAt(fields, "status[1].values[1].key"), "drops");
  EXPECT_EQ(ValueAt(fields, "status[1].values[1].value"), "3");
}

TEST(DynamicDecoderTest, SummarisesLargeByteArrays) {
  sensor_msgs::Image image;
  image.height = 10;
  image.width = 20;
  image.step = 20;
  image.encoding = "mono8";
  image.data.assign(200, 7);
  const auto fields = DecodeWithOwnSchema(image);
  EXPECT_EQ(ValueAt(fields, "data"), "200 bytes");
  EXPECT_EQ(ValueAt(fields, "encoding"), "mono8");
}

// Every message type decodes with exactly its own bytes: this checks the
// schema texts and the serialisers against each other.
TEST(DynamicDecoderTest, EveryTruncationIsAnErrorNamingFieldAndOffset) {
  diagnostic_msgs::DiagnosticArray array;
  array.status.resize(1);
  array.status[0].name = "camera";
  array.status[0].values = {{"k", "v"}};
  const std::vector<std::byte> bytes = SerializeMessage(array);
  const Ros2MsgSchema schema =
      Ros2MsgSchema::Parse(MessageTraits<diagnostic_msgs::DiagnosticArray>::kName,
                           MessageTraits<diagnostic_msgs::DiagnosticArray>::Definition());
  const DynamicDecoder decoder(schema);
  for (std::size_t n = 0; n < bytes.size(); ++n) {
    std::vector<FlatField> fields;
    std::string error;
    const std::vector<std::byte> prefix(bytes.begin(), bytes.begin() + static_cast<long>(n));
    ASSERT_FALSE(decoder.Decode(prefix, &fields, &error)) << "length " << n;
    EXPECT_THAT(error, HasSubstr("diagnostic_msgs/msg/DiagnosticArray")) << error;
    if (n > 4) {
      EXPECT_THAT(error, HasSubstr("offset")) << error;
    }
  }
}

TEST(DynamicDecoderTest, AllProjectSchemasParse) {
  for (const MessageSchema& s : AllMessageSchemas()) {
    EXPECT_NO_THROW(Ros2MsgSchema::Parse(s.name, s.definition())) << s.name;
  }
}

}  // namespace
}  // namespace rover::log
