// Message serialisation: exact bytes, round trips of every type, allocation
// freedom of the real-time types and robustness against damaged input.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include "core/log/cdr/cdr_writer.h"
#include "core/log/msgs/all_msgs.h"
#include "core/time/time.h"
#include "tests/core/log/cdr/random_msgs.h"
#include "tests/support/allocation_counter.h"

namespace rover::log {
namespace {

using ::testing::ElementsAreArray;
using ::testing::HasSubstr;
using ::testing::StartsWith;

// The real-time path copies these through lock-free rings and shared memory.
static_assert(std::is_trivially_copyable_v<builtin_interfaces::Time>);
static_assert(std::is_trivially_copyable_v<std_msgs::Header>);
static_assert(std::is_trivially_copyable_v<sensor_msgs::Imu>);
static_assert(std::is_trivially_copyable_v<nav_msgs::Odometry>);
static_assert(std::is_trivially_copyable_v<geometry_msgs::PoseWithCovarianceStamped>);
static_assert(std::is_trivially_copyable_v<geometry_msgs::TransformStamped>);
static_assert(RosMessage<sensor_msgs::Imu>);
static_assert(!RosMessage<int>);

std::vector<std::byte> Bytes(std::initializer_list<int> values) {
  std::vector<std::byte> out;
  for (const int v : values) out.push_back(static_cast<std::byte>(v));
  return out;
}

std::vector<std::byte> LittleEndianF64(double v) {
  std::vector<std::byte> out(8);
  std::memcpy(out.data(), &v, 8);  // The test hosts are little-endian.
  return out;
}

std::vector<std::byte> Slice(const std::vector<std::byte>& bytes, size_t begin, size_t size) {
  return {bytes.begin() + static_cast<ptrdiff_t>(begin),
          bytes.begin() + static_cast<ptrdiff_t>(begin + size)};
}

void PutU32(std::vector<std::byte>* bytes, size_t at, uint32_t value) {
  std::memcpy(bytes->data() + at, &value, 4);
}

// ---------------------------------------------------------------------------
// Hand-computed encodings.

TEST(MessageBytesTest, Header) {
  std_msgs::Header header;
  header.stamp = {1, 2};
  header.frame_id = "body";
  EXPECT_THAT(SerializeMessage(header),
              ElementsAreArray(Bytes({0x00, 0x01, 0x00, 0x00,  // CDR_LE
                                      0x01, 0x00, 0x00, 0x00,  // stamp.sec
                                      0x02, 0x00, 0x00, 0x00,  // stamp.nanosec
                                      0x05, 0x00, 0x00, 0x00,  // frame_id length incl. NUL
                                      'b',  'o',  'd',  'y',  0x00})));
}

TEST(MessageBytesTest, ImuAlignsFloat64FieldsToEightFromPayloadStart) {
  sensor_msgs::Imu imu;
  imu.header.stamp = {0x01020304, 5};
  imu.header.frame_id = "body";
  imu.orientation = {1.0, 2.0, 3.0, 4.0};
  imu.linear_acceleration_covariance[8] = -7.5;
  const std::vector<std::byte> bytes = SerializeMessage(imu);
  // Header ends at payload offset 17 (buffer 21); orientation.x is aligned to
  // payload offset 24 (buffer 28) with 7 zero bytes of padding.
  EXPECT_THAT(Slice(bytes, 0, 28),
              ElementsAreArray(Bytes({0x00, 0x01, 0x00, 0x00, 0x04, 0x03, 0x02, 0x01, 0x05, 0x00,
                                      0x00, 0x00, 0x05, 0x00, 0x00, 0x00, 'b',  'o',  'd',  'y',
                                      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00})));
  EXPECT_EQ(Slice(bytes, 28, 8), LittleEndianF64(1.0));
  EXPECT_EQ(Slice(bytes, 52, 8), LittleEndianF64(4.0));
  // 4 header + 24 payload before orientation + 3 * (quaternion-or-vector + 9 doubles).
  ASSERT_EQ(bytes.size(), 4u + 24u + (4 + 9 + 3 + 9 + 3 + 9) * 8u);
  EXPECT_EQ(Slice(bytes, bytes.size() - 8, 8), LittleEndianF64(-7.5));
}

TEST(MessageBytesTest, ImuPaddingDependsOnFrameIdLength) {
  sensor_msgs::Imu imu;
  imu.header.frame_id = "ab";  // Header ends at payload 15: one byte of padding.
  imu.orientation.x = 0.5;
  const std::vector<std::byte> bytes = SerializeMessage(imu);
  EXPECT_EQ(bytes[19], std::byte{0});
  EXPECT_EQ(Slice(bytes, 20, 8), LittleEndianF64(0.5));
  EXPECT_EQ(bytes.size(), 4u + 16u + 37u * 8u);
}

TEST(MessageBytesTest, OdometryOffsets) {
  nav_msgs::Odometry odom;
  odom.header.frame_id = "odom";      // Header: payload 0..17.
  odom.child_frame_id = "base_link";  // Length at payload 20, chars end at 34.
  odom.pose.pose.position.x = 9.0;    // Aligned to payload 40 (buffer 44).
  odom.twist.covariance[35] = 3.0;
  const std::vector<std::byte> bytes = SerializeMessage(odom);
  EXPECT_THAT(Slice(bytes, 21, 3), ElementsAreArray(Bytes({0, 0, 0})));
  EXPECT_THAT(Slice(bytes, 24, 4), ElementsAreArray(Bytes({10, 0, 0, 0})));
  EXPECT_THAT(Slice(bytes, 38, 6), ElementsAreArray(Bytes({0, 0, 0, 0, 0, 0})));
  EXPECT_EQ(Slice(bytes, 44, 8), LittleEndianF64(9.0));
  ASSERT_EQ(bytes.size(), 4u + 40u + (7 + 36 + 6 + 36) * 8u);
  EXPECT_EQ(Slice(bytes, bytes.size() - 8, 8), LittleEndianF64(3.0));
}

TEST(MessageBytesTest, DiagnosticStatus) {
  diagnostic_msgs::DiagnosticStatus status;
  status.level = diagnostic_msgs::DiagnosticStatus::kError;
  status.name = "n";
  status.hardware_id = "hw";
  status.values = {{"k", "v"}};
  EXPECT_THAT(SerializeMessage(status),
              ElementsAreArray(Bytes({0x00, 0x01, 0x00, 0x00,                  //
                                      0x02, 0x00, 0x00, 0x00,                  // level + pad
                                      0x02, 0x00, 0x00, 0x00, 'n', 0,   0, 0,  // name + pad
                                      0x01, 0x00, 0x00, 0x00, 0,   0,   0, 0,  // message "" + pad
                                      0x03, 0x00, 0x00, 0x00, 'h', 'w', 0, 0,  // hardware_id
                                      0x01, 0x00, 0x00, 0x00,                  // values count
                                      0x02, 0x00, 0x00, 0x00, 'k', 0,   0, 0,  // key + pad
                                      0x02, 0x00, 0x00, 0x00, 'v', 0})));
}

TEST(MessageBytesTest, ImageDataIsCountThenOctets) {
  sensor_msgs::Image image;
  image.header.frame_id = "c";  // Header: payload 0..14.
  image.height = 1;             // payload 16
  image.width = 2;              // payload 20
  image.encoding = "mono8";     // payload 24..34
  image.is_bigendian = 1;       // payload 34
  image.step = 2;               // payload 36
  image.data = {0xAB, 0xCD};    // count at payload 40, octets 44..46
  const std::vector<std::byte> bytes = SerializeMessage(image);
  ASSERT_EQ(bytes.size(), 4u + 46u);
  EXPECT_THAT(Slice(bytes, 4 + 34, 12),
              ElementsAreArray(Bytes({0x01, 0x00,              // is_bigendian + pad
                                      0x02, 0x00, 0x00, 0x00,  // step
                                      0x02, 0x00, 0x00, 0x00,  // data count
                                      0xAB, 0xCD})));
}

// ---------------------------------------------------------------------------
// Properties of every message type.

template <typename T>
class MessageTest : public ::testing::Test {};
TYPED_TEST_SUITE(MessageTest, cdr_test::AllMessageTypes, cdr_test::MessageTypeName);

TYPED_TEST(MessageTest, RoundTripsRandomContent) {
  using T = TypeParam;
  for (uint64_t seed = 1; seed <= 40; ++seed) {
    cdr_test::RandomMessages random(seed);
    const T original = random.template Make<T>();
    const std::vector<std::byte> bytes = SerializeMessage(original);

    // Decode over a different message: every field must be overwritten.
    T decoded = random.template Make<T>();
    std::string error;
    ASSERT_TRUE(DeserializeMessage(bytes, &decoded, &error)) << "seed " << seed << ": " << error;
    EXPECT_EQ(decoded, original) << "seed " << seed;

    // The fixed-buffer path produces identical bytes and reports exact sizes.
    ASSERT_EQ(SerializedSize(original), bytes.size());
    std::vector<std::byte> buffer(bytes.size());
    ASSERT_EQ(SerializeMessage(original, std::span(buffer)), bytes.size());
    EXPECT_EQ(buffer, bytes);
    EXPECT_EQ(SerializeMessage(original, std::span(buffer).first(bytes.size() - 1)), 0u);
  }
}

TYPED_TEST(MessageTest, IgnoresTrailingBytes) {
  using T = TypeParam;
  cdr_test::RandomMessages random(7);
  const T original = random.template Make<T>();
  std::vector<std::byte> bytes = SerializeMessage(original);
  bytes.resize(bytes.size() + 3);  // DDS may pad the payload to a multiple of 4.
  T decoded;
  ASSERT_TRUE(DeserializeMessage(bytes, &decoded));
  EXPECT_EQ(decoded, original);
}

TYPED_TEST(MessageTest, EveryTruncationFailsWithFieldAndOffset) {
  using T = TypeParam;
  const std::string name(MessageTraits<T>::kName);
  for (uint64_t seed = 1; seed <= 3; ++seed) {
    cdr_test::RandomMessages random(seed);
    const std::vector<std::byte> bytes = SerializeMessage(random.template Make<T>());
    for (size_t n = 0; n < bytes.size(); ++n) {
      // An exactly sized heap copy, so ASan flags any read past the end.
      const std::vector<std::byte> prefix = Slice(bytes, 0, n);
      T decoded;
      std::string error;
      ASSERT_FALSE(DeserializeMessage(prefix, &decoded, &error)) << "prefix " << n;
      EXPECT_THAT(error, StartsWith(name + ": ")) << "prefix " << n;
      EXPECT_THAT(error, HasSubstr("at offset ")) << "prefix " << n;
      if (n >= CdrWriter::kEncapsulationHeaderSize) {
        EXPECT_THAT(error, HasSubstr("field '")) << "prefix " << n;
      }
    }
  }
}

TYPED_TEST(MessageTest, CorruptedInputNeverCrashesOrOverAllocates) {
  using T = TypeParam;
  std::mt19937_64 rng(99);
  cdr_test::RandomMessages random(5);
  const std::vector<std::byte> bytes = SerializeMessage(random.template Make<T>());
  // The bytes allocated while decoding must stay proportional to the input
  // (an element struct is at most ~8x its minimum wire size, and only one
  // sequence per nesting level is being filled when decoding fails): a length
  // read from corrupted bytes must never be trusted for allocation.
  const size_t allocation_bound = 64 * bytes.size() + 4096;
  auto decode = [&](const std::vector<std::byte>& input) {
    T decoded;
    std::string error;
    const rover::testing::ScopedAllocationCheck check;
    const bool ok = DeserializeMessage(input, &decoded, &error);
    EXPECT_LE(check.allocated_bytes(), allocation_bound);
    if (!ok) {
      EXPECT_THAT(error, StartsWith(std::string(MessageTraits<T>::kName) + ": "));
    }
  };
  // Random byte flips.
  for (int i = 0; i < 300; ++i) {
    std::vector<std::byte> damaged = bytes;
    const int flips = 1 + static_cast<int>(rng() % 3);
    for (int f = 0; f < flips; ++f) {
      damaged[4 + rng() % (damaged.size() - 4)] = static_cast<std::byte>(rng());
    }
    decode(damaged);
  }
  // Huge lengths at every 4-aligned payload position (where length prefixes live).
  for (size_t at = 4; at + 4 <= bytes.size(); at += 4) {
    for (const uint32_t value : {0xFFFFFFFFu, 0x7FFFFFFFu, 0x01000000u}) {
      std::vector<std::byte> damaged = bytes;
      PutU32(&damaged, at, value);
      decode(damaged);
    }
  }
}

TYPED_TEST(MessageTest, HasRosTypeName) {
  const std::string_view name = MessageTraits<TypeParam>::kName;
  const size_t first = name.find('/');
  ASSERT_NE(first, std::string_view::npos);
  EXPECT_EQ(name.substr(first, 5), "/msg/");
  EXPECT_EQ(name.find('/', first + 5), std::string_view::npos);
}

// ---------------------------------------------------------------------------
// Real-time properties.

template <typename T>
void ExpectSerializesWithoutAllocation(const T& msg) {
  std::array<std::byte, 2048> buffer;
  std::array<std::byte, 16> small_buffer;
  const rover::testing::ScopedAllocationCheck check;
  const size_t size = SerializedSize(msg);
  const size_t written = SerializeMessage(msg, std::span(buffer));
  const size_t overflow = SerializeMessage(msg, std::span(small_buffer));
  const uint64_t allocations = check.allocations();
  EXPECT_EQ(allocations, 0u) << MessageTraits<T>::kName;
  EXPECT_EQ(written, size);
  EXPECT_EQ(overflow, 0u);
}

TEST(RealTimeTest, RealTimeMessagesSerializeWithoutAllocation) {
  cdr_test::RandomMessages random(11);
  ExpectSerializesWithoutAllocation(random.Make<std_msgs::Header>());
  ExpectSerializesWithoutAllocation(random.Make<sensor_msgs::Imu>());
  ExpectSerializesWithoutAllocation(random.Make<nav_msgs::Odometry>());
  ExpectSerializesWithoutAllocation(random.Make<geometry_msgs::PoseWithCovarianceStamped>());
  ExpectSerializesWithoutAllocation(random.Make<geometry_msgs::TransformStamped>());
}

TEST(RealTimeTest, RealTimeMessagesDeserializeWithoutAllocation) {
  cdr_test::RandomMessages random(12);
  const sensor_msgs::Imu imu = random.Make<sensor_msgs::Imu>();
  const std::vector<std::byte> bytes = SerializeMessage(imu);
  sensor_msgs::Imu decoded;
  const rover::testing::ScopedAllocationCheck check;
  const bool ok = DeserializeMessage(bytes, &decoded);
  EXPECT_EQ(check.allocations(), 0u);
  EXPECT_TRUE(ok);
  EXPECT_EQ(decoded, imu);
}

TEST(RealTimeTest, MessagesSurviveMemcpy) {
  // What a lock-free ring does with the real-time messages.
  cdr_test::RandomMessages random(13);
  const nav_msgs::Odometry odom = random.Make<nav_msgs::Odometry>();
  alignas(nav_msgs::Odometry) std::array<std::byte, sizeof(nav_msgs::Odometry)> slot;
  std::memcpy(slot.data(), &odom, sizeof odom);
  nav_msgs::Odometry copy;
  std::memcpy(&copy, slot.data(), sizeof copy);
  EXPECT_EQ(copy, odom);
  EXPECT_EQ(SerializeMessage(copy), SerializeMessage(odom));
}

// ---------------------------------------------------------------------------
// Specific decoding errors.

TEST(DecodeErrorTest, HugeFrameIdLengthNamesNestedField) {
  sensor_msgs::Imu imu;
  imu.header.frame_id = "body";
  std::vector<std::byte> bytes = SerializeMessage(imu);
  PutU32(&bytes, 12, 4'000'000);  // header.frame_id length prefix.
  sensor_msgs::Imu decoded;
  std::string error;
  EXPECT_FALSE(DeserializeMessage(bytes, &decoded, &error));
  EXPECT_EQ(error,
            "sensor_msgs/msg/Imu: field 'header.frame_id' at offset 12: string length "
            "4000000 exceeds remaining " +
                std::to_string(bytes.size() - 16) + " bytes");
}

TEST(DecodeErrorTest, FrameIdLongerThanCapacityIsRejected) {
  std::vector<std::byte> bytes;
  {
    CdrWriter writer(&bytes);
    writer.WriteI32(1);
    writer.WriteU32(2);
    writer.WriteString(std::string(100, 'f'));
  }
  std_msgs::Header header;
  std::string error;
  EXPECT_FALSE(DeserializeMessage(bytes, &header, &error));
  EXPECT_EQ(error,
            "std_msgs/msg/Header: field 'frame_id' at offset 12: string of 100 bytes exceeds "
            "the inline capacity of 63");
}

TEST(DecodeErrorTest, FrameIdWithEmbeddedNulIsRejected) {
  std::vector<std::byte> bytes;
  {
    CdrWriter writer(&bytes);
    writer.WriteI32(1);
    writer.WriteU32(2);
    writer.WriteString(std::string_view("a\0b", 3));
    writer.WriteString("child");
  }
  geometry_msgs::TransformStamped transform;
  std::string error;
  EXPECT_FALSE(DeserializeMessage(bytes, &transform, &error));
  EXPECT_THAT(error, HasSubstr("field 'header.frame_id' at offset 12: string contains an "
                               "embedded NUL"));
}

TEST(DecodeErrorTest, HugeSequenceCountIsRejectedBeforeAllocating) {
  tf2_msgs::TFMessage tf;
  tf.transforms.resize(2);
  std::vector<std::byte> bytes = SerializeMessage(tf);
  PutU32(&bytes, 4, 0xFFFFFFFF);
  tf2_msgs::TFMessage decoded;
  std::string error;
  const rover::testing::ScopedAllocationCheck check;
  EXPECT_FALSE(DeserializeMessage(bytes, &decoded, &error));
  EXPECT_LT(check.allocated_bytes(), 4096u);  // Just the error message.
  EXPECT_EQ(error,
            "tf2_msgs/msg/TFMessage: field 'transforms' at offset 4: sequence length "
            "4294967295 exceeds remaining " +
                std::to_string(bytes.size() - 8) + " bytes (elements take at least 72 bytes)");
}

TEST(DecodeErrorTest, ErrorsInsideSequencesNameTheElement) {
  diagnostic_msgs::DiagnosticArray array;
  array.header.frame_id = "diag";
  array.status.resize(2);
  array.status[1].name = "gps";
  // The key is longer than the 8-byte minimum element size, so some
  // truncations pass the count check and fail inside the key itself.
  array.status[1].values = {{"gps_fix_quality", "3d"}};
  const std::vector<std::byte> bytes = SerializeMessage(array);
  bool saw_key = false;
  bool saw_value = false;
  bool saw_name = false;
  for (size_t n = 0; n < bytes.size(); ++n) {
    diagnostic_msgs::DiagnosticArray decoded;
    std::string error;
    ASSERT_FALSE(DeserializeMessage(Slice(bytes, 0, n), &decoded, &error));
    saw_key |= error.find("field 'status[1].values[0].key'") != std::string::npos;
    saw_value |= error.find("field 'status[1].values[0].value'") != std::string::npos;
    saw_name |= error.find("field 'status[1].name'") != std::string::npos;
  }
  EXPECT_TRUE(saw_key);
  EXPECT_TRUE(saw_value);
  EXPECT_TRUE(saw_name);
}

TEST(DecodeErrorTest, NullErrorPointerIsAllowed) {
  const std::vector<std::byte> bytes = Bytes({0x00, 0x01, 0x00, 0x00});
  std_msgs::Header header;
  EXPECT_FALSE(DeserializeMessage(bytes, &header));
}

// ---------------------------------------------------------------------------
// Time conversion.

TEST(RosTimeTest, SplitsNanoseconds) {
  EXPECT_EQ(ToRosTime(Time::FromNanoseconds(0)), (builtin_interfaces::Time{0, 0}));
  EXPECT_EQ(ToRosTime(Time::FromNanoseconds(1'500'000'000)),
            (builtin_interfaces::Time{1, 500'000'000}));
  EXPECT_EQ(ToRosTime(Time::FromNanoseconds(999'999'999)),
            (builtin_interfaces::Time{0, 999'999'999}));
}

TEST(RosTimeTest, NegativeTimesFloorSoNanosecStaysInRange) {
  EXPECT_EQ(ToRosTime(Time::FromNanoseconds(-1)), (builtin_interfaces::Time{-1, 999'999'999}));
  EXPECT_EQ(ToRosTime(Time::FromNanoseconds(-1'700'000'000)),
            (builtin_interfaces::Time{-2, 300'000'000}));
  EXPECT_EQ(ToRosTime(Time::FromNanoseconds(-2'000'000'000)), (builtin_interfaces::Time{-2, 0}));
}

TEST(RosTimeTest, SaturatesOutsideInt32Seconds) {
  EXPECT_EQ(ToRosTime(Time::Max()), (builtin_interfaces::Time{2147483647, 999'999'999}));
  EXPECT_EQ(ToRosTime(Time::FromNanoseconds(std::numeric_limits<int64_t>::min())),
            (builtin_interfaces::Time{-2147483647 - 1, 0}));
}

TEST(RosTimeTest, RoundTripsEveryRepresentableTime) {
  static_assert(FromRosTime(ToRosTime(Time::FromNanoseconds(12'345))).nanoseconds() == 12'345);
  std::mt19937_64 rng(3);
  const int64_t limit = int64_t{2147483647} * 1'000'000'000;
  std::uniform_int_distribution<int64_t> ns(-limit, limit);
  for (int i = 0; i < 10000; ++i) {
    const Time t = Time::FromNanoseconds(ns(rng));
    const builtin_interfaces::Time ros = ToRosTime(t);
    EXPECT_LT(ros.nanosec, 1'000'000'000u);
    EXPECT_EQ(FromRosTime(ros), t);
  }
  EXPECT_EQ(FromRosTime({3, 1'500'000'000}), Time::FromNanoseconds(4'500'000'000));
}

}  // namespace
}  // namespace rover::log
