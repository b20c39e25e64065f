#include "core/config/config.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

namespace rover {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

// A YAML file in the temp directory, removed when the test ends. Tests check
// line numbers against the literal text they write, so every test file starts
// at line 1 with no leading newline.
class TempYamlFile {
 public:
  explicit TempYamlFile(const std::string& contents) {
    const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = (std::filesystem::temp_directory_path() /
             (std::string("rover_config_test_") + info->name() + "_" + std::to_string(::getpid()) +
              "_" + std::to_string(counter_++) + ".yaml"))
                .string();
    std::ofstream(path_) << contents;
  }
  ~TempYamlFile() { std::filesystem::remove(path_); }
  TempYamlFile(const TempYamlFile&) = delete;
  TempYamlFile& operator=(const TempYamlFile&) = delete;

  const std::string& path() const { return path_; }

 private:
  static inline int counter_ = 0;
  std::string path_;
};

// Runs f and returns the ConfigError message, or "<no error>".
template <typename F>
std::string ErrorOf(F&& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "<no error>";
}

ConfigNode Load(std::string_view yaml) { return ConfigNode::LoadString(yaml, "test.yaml"); }

// ------------------------------------------------------- locations in errors

constexpr char kImuYaml[] =
    "imu:\n"                                         // 1
    "  rate_hz: 5000\n"                              // 2
    "  noise:\n"                                     // 3
    "    accel_noise_density_m_s2_sqrt_hz: 0.002\n"  // 4
    "    gyro_noise_density_rad_s_sqrt_hz: fast\n"   // 5
    "  model: bmi088\n";                             // 6

TEST(ConfigErrorTest, OutOfRangeNamesFullPathAndLine) {
  const TempYamlFile file(kImuYaml);
  const ConfigNode root = ConfigNode::LoadFile(file.path());
  EXPECT_EQ(ErrorOf([&] { root.Child("imu").GetInRange<double>("rate_hz", 100, 1000); }),
            file.path() + ":2: imu.rate_hz: expected a number in [100, 1000], found 5000");
  EXPECT_EQ(ErrorOf([&] { root.Child("imu").GetInRange<int>("rate_hz", 100, 1000); }),
            file.path() + ":2: imu.rate_hz: expected an integer in [100, 1000], found 5000");
  EXPECT_EQ(ErrorOf([&] { root.Child("imu").GetInRange<double>("rate_hz", 0.5, 1e3, 7.0); }),
            file.path() + ":2: imu.rate_hz: expected a number in [0.5, 1000], found 5000");
}

TEST(ConfigErrorTest, WrongTypeNamesNestedPathAndLine) {
  const TempYamlFile file(kImuYaml);
  const ConfigNode noise = ConfigNode::LoadFile(file.path()).Child("imu").Child("noise");
  EXPECT_EQ(noise.Path(), "imu.noise");
  EXPECT_EQ(ErrorOf([&] { noise.Get<double>("gyro_noise_density_rad_s_sqrt_hz"); }),
            file.path() +
                ":5: imu.noise.gyro_noise_density_rad_s_sqrt_hz: expected a number, found fast");
  EXPECT_DOUBLE_EQ(noise.Get<double>("accel_noise_density_m_s2_sqrt_hz"), 0.002);
}

TEST(ConfigErrorTest, MissingKeyPointsAtTheEnclosingMap) {
  const TempYamlFile file(kImuYaml);
  const ConfigNode root = ConfigNode::LoadFile(file.path());
  const ConfigNode noise = root.Child("imu").Child("noise");
  EXPECT_EQ(ErrorOf([&] { noise.Get<double>("gyro_random_walk_rad_s2_sqrt_hz"); }),
            file.path() + ":3: imu.noise.gyro_random_walk_rad_s2_sqrt_hz: missing required key");
  EXPECT_EQ(ErrorOf([&] { root.Child("gps"); }), file.path() + ":1: gps: missing required key");
}

TEST(ConfigErrorTest, ChildMustBeAMap) {
  const ConfigNode root = Load("a: 1\nb:\nc: [1]\n");
  EXPECT_EQ(ErrorOf([&] { root.Child("a"); }), "test.yaml:1: a: expected a map, found 1");
  EXPECT_EQ(ErrorOf([&] { root.Child("b"); }),
            "test.yaml:2: b: expected a map, found null (write {} for an empty map)");
  EXPECT_EQ(ErrorOf([&] { root.Child("c"); }), "test.yaml:3: c: expected a map, found a list");
  EXPECT_EQ(ErrorOf([&] { root.Child("a").Get<int>("x"); }),
            "test.yaml:1: a: expected a map, found 1");
}

TEST(ConfigErrorTest, SyntaxErrorHasFileAndLine) {
  const TempYamlFile file(
      "a: 1\n"
      "b: [1, 2\n"
      "c: 3\n");
  EXPECT_THAT(ErrorOf([&] { ConfigNode::LoadFile(file.path()); }),
              AllOf(StartsWith(file.path() + ":3: YAML syntax error at column"),
                    HasSubstr("end of sequence flow not found")));
  EXPECT_THAT(ErrorOf([] { Load("a: 1\n  b: 2\n"); }), StartsWith("test.yaml:2: YAML syntax"));
}

TEST(ConfigErrorTest, MissingFile) {
  EXPECT_EQ(ErrorOf([] { ConfigNode::LoadFile("/nonexistent/rover.yaml"); }),
            "/nonexistent/rover.yaml: cannot open file");
}

TEST(ConfigErrorTest, DuplicateKeysAreRejectedAtLoad) {
  EXPECT_EQ(ErrorOf([] { Load("imu:\n  rate_hz: 1\n  bias: 0\n  rate_hz: 2\n"); }),
            "test.yaml:4: imu.rate_hz: duplicate key (first defined at line 2)");
  EXPECT_EQ(ErrorOf([] { Load("cams:\n  - {a: 1, a: 2}\n"); }),
            "test.yaml:2: cams[0].a: duplicate key (first defined at line 2)");
}

TEST(ConfigErrorTest, TopLevelMustBeAMapOrList) {
  EXPECT_EQ(ErrorOf([] { Load("42\n"); }),
            "test.yaml:1: expected a map at the top level, found 42");
  EXPECT_EQ(Load("[1, 2]").Items().size(), 2u);
}

TEST(ConfigErrorTest, FailLocatesCrossFieldErrors) {
  const ConfigNode root = Load("limits:\n  min_speed_m_s: 2.0\n  max_speed_m_s: 1.0\n");
  const ConfigNode limits = root.Child("limits");
  EXPECT_EQ(ErrorOf([&] { limits.Fail("max_speed_m_s", "must exceed min_speed_m_s"); }),
            "test.yaml:3: limits.max_speed_m_s: must exceed min_speed_m_s");
  EXPECT_EQ(ErrorOf([&] { limits.Fail("", "inconsistent"); }), "test.yaml:1: limits: inconsistent");
  EXPECT_EQ(ErrorOf([&] { limits.Fail("absent", "needed when x"); }),
            "test.yaml:1: limits.absent: needed when x");
  EXPECT_EQ(limits.Where(), "test.yaml:1: limits");
  EXPECT_EQ(root.Where(), "test.yaml:1");
}

// ----------------------------------------------------------------- numbers

TEST(ConfigNumberTest, IntegersRejectFractionsAndOutOfRange) {
  const ConfigNode n = Load(
      "frac: 1.5\n"
      "big: 300\n"
      "neg: -1\n"
      "sci: 1e3\n"
      "whole: 2.0\n"
      "hex: 0x1F\n"
      "min64: -9223372036854775808\n"
      "over64: 9223372036854775808\n"
      "maxu64: 18446744073709551615\n"
      "word: ten\n"
      "inf: .inf\n");
  EXPECT_EQ(ErrorOf([&] { n.Get<int>("frac"); }),
            "test.yaml:1: frac: expected an integer, found 1.5");
  EXPECT_EQ(ErrorOf([&] { n.Get<uint8_t>("big"); }),
            "test.yaml:2: big: expected an integer in [0, 255], found 300");
  EXPECT_EQ(ErrorOf([&] { n.Get<int8_t>("big"); }),
            "test.yaml:2: big: expected an integer in [-128, 127], found 300");
  EXPECT_EQ(ErrorOf([&] { n.Get<uint32_t>("neg"); }),
            "test.yaml:3: neg: expected an integer in [0, 4294967295], found -1");
  EXPECT_EQ(n.Get<int>("neg"), -1);
  EXPECT_EQ(n.Get<int>("sci"), 1000);
  EXPECT_EQ(n.Get<uint16_t>("whole"), 2);
  EXPECT_EQ(n.Get<int>("hex"), 31);
  EXPECT_EQ(n.Get<int64_t>("min64"), std::numeric_limits<int64_t>::min());
  EXPECT_THAT(ErrorOf([&] { n.Get<int64_t>("over64"); }),
              HasSubstr("over64: expected an integer in [-9223372036854775808, "));
  EXPECT_EQ(n.Get<uint64_t>("over64"), 9223372036854775808ULL);
  EXPECT_EQ(n.Get<uint64_t>("maxu64"), std::numeric_limits<uint64_t>::max());
  EXPECT_EQ(ErrorOf([&] { n.Get<long>("word"); }),
            "test.yaml:10: word: expected an integer, found ten");
  EXPECT_EQ(ErrorOf([&] { n.Get<int>("inf"); }),
            "test.yaml:11: inf: expected an integer, found .inf");
}

TEST(ConfigNumberTest, DoublesRejectNonFiniteUnlessAllowed) {
  const ConfigNode n = Load(
      "nan: .nan\n"
      "inf: .inf\n"
      "ninf: -.Inf\n"
      "huge: 1e400\n"
      "plain: -2.5e-3\n"
      "int: 7\n"
      "word: inf\n");
  EXPECT_EQ(ErrorOf([&] { n.Get<double>("nan"); }),
            "test.yaml:1: nan: expected a finite number, found .nan");
  EXPECT_EQ(ErrorOf([&] { n.Get<double>("inf"); }),
            "test.yaml:2: inf: expected a finite number, found .inf");
  EXPECT_EQ(ErrorOf([&] { n.GetInRange<double>("nan", 0, 1); }),
            "test.yaml:1: nan: expected a finite number, found .nan");
  EXPECT_TRUE(std::isnan(n.GetAllowNonFinite("nan")));
  EXPECT_EQ(n.GetAllowNonFinite("inf"), std::numeric_limits<double>::infinity());
  EXPECT_EQ(n.GetAllowNonFinite("ninf"), -std::numeric_limits<double>::infinity());
  EXPECT_EQ(n.GetAllowNonFinite("absent", 3.0), 3.0);
  EXPECT_EQ(ErrorOf([&] { n.Get<double>("huge"); }),
            "test.yaml:4: huge: number out of range for double, found 1e400");
  EXPECT_EQ(n.Get<double>("plain"), -2.5e-3);
  EXPECT_EQ(n.Get<double>("int"), 7.0);
  EXPECT_EQ(n.Get<float>("plain"), -2.5e-3f);
  EXPECT_EQ(ErrorOf([&] { n.Get<double>("word"); }),
            "test.yaml:7: word: expected a number, found inf");
  EXPECT_EQ(ErrorOf([&] { n.Get<float>("huge"); }),
            "test.yaml:4: huge: number out of range for double, found 1e400");
}

TEST(ConfigNumberTest, QuotedNumbersAndBooleansAreStrings) {
  const ConfigNode n = Load("rate: \"200\"\nflag: 'true'\nyes_flag: yes\n");
  EXPECT_EQ(ErrorOf([&] { n.Get<double>("rate"); }),
            "test.yaml:1: rate: expected a number, found \"200\"");
  EXPECT_EQ(n.Get<std::string>("rate"), "200");
  EXPECT_EQ(ErrorOf([&] { n.Get<bool>("flag"); }),
            "test.yaml:2: flag: expected a boolean (true or false), found \"true\"");
  EXPECT_EQ(ErrorOf([&] { n.Get<bool>("yes_flag"); }),
            "test.yaml:3: yes_flag: expected a boolean (true or false), found yes");
}

TEST(ConfigNumberTest, RangesAreInclusive) {
  const ConfigNode n = Load("lo: 100\nhi: 1000\n");
  EXPECT_EQ(n.GetInRange<int>("lo", 100, 1000), 100);
  EXPECT_EQ(n.GetInRange<double>("hi", 100, 1000), 1000.0);
  EXPECT_EQ(n.GetInRange<double>("absent", 0, 1, 0.5), 0.5);
  EXPECT_EQ(ErrorOf([&] { n.GetInRange<uint32_t>("lo", 101, 200); }),
            "test.yaml:1: lo: expected an integer in [101, 200], found 100");
  EXPECT_EQ(ErrorOf([&] { n.GetInRange<double>("lo", 0.001, 0.1); }),
            "test.yaml:1: lo: expected a number in [0.001, 0.1], found 100");
}

// --------------------------------------------------------- other scalar types

TEST(ConfigValueTest, BoolsStringsAndDefaults) {
  const ConfigNode n = Load(
      "on: true\n"
      "off: False\n"
      "name: cam0\n"
      "empty: \"\"\n"
      "null_value:\n"
      "list: [a]\n");
  EXPECT_TRUE(n.Get<bool>("on"));
  EXPECT_FALSE(n.Get<bool>("off"));
  EXPECT_EQ(n.Get<std::string>("name"), "cam0");
  EXPECT_EQ(n.Get<std::string>("empty"), "");
  EXPECT_EQ(n.Get<std::string>("absent", "fallback"), "fallback");
  EXPECT_EQ(n.Get<double>("absent", 2), 2.0);
  EXPECT_EQ(n.Get<bool>("absent", true), true);
  // Present but empty is an error, never the default.
  EXPECT_EQ(ErrorOf([&] { n.Get<std::string>("null_value", "fallback"); }),
            "test.yaml:5: null_value: expected a string, found null");
  EXPECT_EQ(ErrorOf([&] { n.Get<double>("null_value", 1.0); }),
            "test.yaml:5: null_value: expected a number, found null");
  EXPECT_EQ(ErrorOf([&] { n.Get<std::string>("list"); }),
            "test.yaml:6: list: expected a string, found a list");
  EXPECT_TRUE(n.Has("name"));
  EXPECT_FALSE(n.Has("nope"));
}

TEST(ConfigValueTest, ListsOfScalars) {
  const ConfigNode n = Load(
      "gains: [1.0, 2, 3e-1]\n"
      "topics:\n"
      "  - /imu\n"
      "  - /cam0\n"
      "bad:\n"
      "  - 1.0\n"
      "  - x\n"
      "scalar: 3\n");
  EXPECT_THAT(n.Get<std::vector<double>>("gains"), ::testing::ElementsAre(1.0, 2.0, 0.3));
  EXPECT_THAT(n.Get<std::vector<std::string>>("topics"), ::testing::ElementsAre("/imu", "/cam0"));
  EXPECT_EQ(ErrorOf([&] { n.Get<std::vector<double>>("bad"); }),
            "test.yaml:7: bad[1]: expected a number, found x");
  EXPECT_EQ(ErrorOf([&] { n.Get<std::vector<int>>("gains"); }),
            "test.yaml:1: gains[2]: expected an integer, found 3e-1");
  EXPECT_EQ(ErrorOf([&] { n.Get<std::vector<double>>("scalar"); }),
            "test.yaml:8: scalar: expected a list, found 3");
  EXPECT_TRUE(n.Get<std::vector<double>>("absent", {}).empty());
}

enum class Compression { kNone, kLz4, kZstd };

TEST(ConfigValueTest, EnumsListAllowedNames) {
  const ConfigNode n = Load("a: zstd\nb: gzip\nc: [zstd]\n");
  const EnumNames<Compression> names = {
      {"none", Compression::kNone}, {"lz4", Compression::kLz4}, {"zstd", Compression::kZstd}};
  EXPECT_EQ(n.GetEnum<Compression>("a", names), Compression::kZstd);
  EXPECT_EQ(n.GetEnum<Compression>("absent", names, Compression::kLz4), Compression::kLz4);
  EXPECT_EQ(ErrorOf([&] { n.GetEnum<Compression>("b", names); }),
            "test.yaml:2: b: expected one of \"none\", \"lz4\", \"zstd\", found gzip");
  EXPECT_EQ(ErrorOf([&] { n.GetEnum<Compression>("b", names, Compression::kNone); }),
            "test.yaml:2: b: expected one of \"none\", \"lz4\", \"zstd\", found gzip");
  EXPECT_EQ(ErrorOf([&] { n.GetEnum<Compression>("c", names); }),
            "test.yaml:3: c: expected a name, found a list");
  EXPECT_EQ(ErrorOf([&] { n.GetEnum<Compression>("absent", names); }),
            "test.yaml:1: absent: missing required key");
}

// ------------------------------------------------------------------- Eigen

TEST(ConfigEigenTest, VectorsAndMatrices) {
  const ConfigNode n = Load(
      "p: [1, 2, 3]\n"              // 1
      "short: [1, 2]\n"             // 2
      "T_body_cam:\n"               // 3
      "  - [1, 0, 0, 0.1]\n"        // 4
      "  - [0, 1, 0, 0.0]\n"        // 5
      "  - [0, 0, 1, 0.2]\n"        // 6
      "  - [0, 0, 0, 1]\n"          // 7
      "flat: [1, 2, 3, 4]\n"        // 8
      "ragged:\n"                   // 9
      "  - [1, 2]\n"                // 10
      "  - [3]\n"                   // 11
      "odd: [1, 2, 3]\n"            // 12
      "bad_elem: [1, nope, 3]\n");  // 13
  EXPECT_EQ(n.Get<Eigen::Vector3d>("p"), Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(n.Get<Eigen::Vector3i>("p"), Eigen::Vector3i(1, 2, 3));
  EXPECT_EQ(n.Get<Eigen::RowVector3d>("p"), Eigen::RowVector3d(1, 2, 3));
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T(0, 3) = 0.1;
  T(2, 3) = 0.2;
  EXPECT_EQ(n.Get<Eigen::Matrix4d>("T_body_cam"), T);
  Eigen::Matrix2d flat;
  flat << 1, 2, 3, 4;  // Row-major, as written.
  EXPECT_EQ(n.Get<Eigen::Matrix2d>("flat"), flat);
  EXPECT_EQ(n.Get<Eigen::Vector4d>("flat"), Eigen::Vector4d(1, 2, 3, 4));

  EXPECT_EQ(ErrorOf([&] { n.Get<Eigen::Vector3d>("short"); }),
            "test.yaml:2: short: expected a list of 3 numbers, found a list of 2 elements");
  EXPECT_EQ(ErrorOf([&] { n.Get<Eigen::Vector3d>("T_body_cam"); }),
            "test.yaml:3: T_body_cam: expected a list of 3 numbers, found a list of 4 elements");
  EXPECT_EQ(ErrorOf([&] { n.Get<Eigen::Matrix3d>("T_body_cam"); }),
            "test.yaml:3: T_body_cam: expected a 3x3 matrix, as a list of 3 rows of 3 numbers "
            "or a flat row-major list of 9 numbers, found a list of 4 elements");
  EXPECT_EQ(ErrorOf([&] { n.Get<Eigen::Matrix2d>("ragged"); }),
            "test.yaml:11: ragged[1]: expected a list of 2 numbers, found a list of 1 elements");
  EXPECT_EQ(ErrorOf([&] { n.Get<Eigen::Matrix2d>("odd"); }),
            "test.yaml:12: odd: expected a 2x2 matrix, as a list of 2 rows of 2 numbers or a "
            "flat row-major list of 4 numbers, found a list of 3 elements");
  EXPECT_EQ(ErrorOf([&] { n.Get<Eigen::Vector3d>("bad_elem"); }),
            "test.yaml:13: bad_elem[1]: expected a number, found nope");
  EXPECT_EQ(ErrorOf([&] { n.Get<Eigen::Vector3d>("absent"); }),
            "test.yaml:1: absent: missing required key");
  EXPECT_EQ(n.Get<Eigen::Vector2d>("absent", Eigen::Vector2d(5, 6)), Eigen::Vector2d(5, 6));
}

// ----------------------------------------------------------- unknown keys

TEST(ConfigUnknownKeysTest, ListsEveryUnusedKeyWithItsLine) {
  const ConfigNode root = Load(
      "imu:\n"                  // 1
      "  rate_hz: 200\n"        // 2
      "  rate_hzz: 400\n"       // 3
      "  bias_model: rw\n"      // 4
      "  use_magnetomter: 1\n"  // 5
      "unused_top: 1\n");       // 6
  const ConfigNode imu = root.Child("imu");
  EXPECT_EQ(imu.Get<double>("rate_hz"), 200.0);
  EXPECT_FALSE(imu.Get<bool>("use_magnetometer", false));
  EXPECT_EQ(ErrorOf([&] { imu.CheckNoUnknownKeys(); }),
            "test.yaml:3: imu.rate_hzz: unknown key\n"
            "test.yaml:4: imu.bias_model: unknown key\n"
            "test.yaml:5: imu.use_magnetomter: unknown key (did you mean \"use_magnetometer\"?)");
  // Non-recursive on the root: only its own keys.
  EXPECT_EQ(ErrorOf([&] { root.CheckNoUnknownKeys(); }), "test.yaml:6: unused_top: unknown key");
  EXPECT_THAT(ErrorOf([&] { root.CheckNoUnknownKeysRecursive(); }),
              AllOf(HasSubstr("test.yaml:3: imu.rate_hzz: unknown key\n"),
                    HasSubstr("test.yaml:6: unused_top: unknown key")));
}

TEST(ConfigUnknownKeysTest, TrackingIsSharedAcrossChildCopies) {
  const ConfigNode root = Load("a:\n  x: 1\n  y: 2\n");
  root.Child("a").Get<int>("x");
  const ConfigNode again = root.Child("a");
  EXPECT_EQ(ErrorOf([&] { again.CheckNoUnknownKeys(); }), "test.yaml:3: a.y: unknown key");
  const ConfigNode copy = again;
  copy.Get<int>("y");
  EXPECT_EQ(ErrorOf([&] { root.CheckNoUnknownKeysRecursive(); }), "<no error>");
  EXPECT_EQ(ErrorOf([&] { again.CheckNoUnknownKeys(); }), "<no error>");
}

TEST(ConfigUnknownKeysTest, RecursiveCheckCoversListsAndUnreadSections) {
  const ConfigNode root = Load(
      "cameras:\n"            // 1
      "  - name: cam0\n"      // 2
      "    rate_hz: 20\n"     // 3
      "  - name: cam1\n"      // 4
      "    rate_hz: 20\n"     // 5
      "    exposure: 3\n"     // 6
      "gps:\n"                // 7
      "  port: /dev/ttyS1\n"  // 8
      "log:\n"                // 9
      "  dir: /tmp\n");       // 10
  const std::vector<ConfigNode> cameras = root.ChildList("cameras");
  ASSERT_EQ(cameras.size(), 2u);
  for (const ConfigNode& cam : cameras) {
    cam.Get<std::string>("name");
    cam.Get<int>("rate_hz");
  }
  EXPECT_EQ(cameras[1].Path(), "cameras[1]");
  EXPECT_EQ(cameras[1].Where(), "test.yaml:4: cameras[1]");
  // gps was only tested for, so none of its keys were understood.
  EXPECT_TRUE(root.Has("gps"));
  root.Child("log").Get<std::string>("dir");
  EXPECT_EQ(ErrorOf([&] { root.CheckNoUnknownKeysRecursive(); }),
            "test.yaml:6: cameras[1].exposure: unknown key\n"
            "test.yaml:8: gps.port: unknown key");
}

TEST(ConfigUnknownKeysTest, KeysEnumeratesDataKeyedMaps) {
  const ConfigNode root = Load("topics:\n  imu: {depth: 10}\n  cam0: {depth: 2, qos: x}\n");
  const ConfigNode topics = root.Child("topics");
  EXPECT_THAT(topics.Keys(), ::testing::ElementsAre("imu", "cam0"));
  for (const std::string& name : topics.Keys()) topics.Child(name).Get<int>("depth");
  EXPECT_EQ(ErrorOf([&] { root.CheckNoUnknownKeysRecursive(); }),
            "test.yaml:3: topics.cam0.qos: unknown key");
}

TEST(ConfigUnknownKeysTest, EmptyDocumentUsesDefaults) {
  const ConfigNode root = Load("# only a comment\n");
  EXPECT_EQ(root.Get<int>("depth", 4), 4);
  EXPECT_EQ(ErrorOf([&] { root.Get<int>("depth"); }), "test.yaml: depth: missing required key");
  EXPECT_EQ(ErrorOf([&] { root.CheckNoUnknownKeysRecursive(); }), "<no error>");
}

// --------------------------------------------- the intended usage pattern

// What a component's options look like: a plain struct, a static Load that
// reads exactly its own section and validates as it goes, and cross-field
// checks reported through Fail so they carry file:line too.
struct NoiseOptions {
  double gyro_noise_density_rad_s_sqrt_hz = 0.0;
  double accel_noise_density_m_s2_sqrt_hz = 0.0;

  static NoiseOptions Load(const ConfigNode& node) {
    NoiseOptions o;
    o.gyro_noise_density_rad_s_sqrt_hz =
        node.GetInRange<double>("gyro_noise_density_rad_s_sqrt_hz", 0.0, 1.0);
    o.accel_noise_density_m_s2_sqrt_hz =
        node.GetInRange<double>("accel_noise_density_m_s2_sqrt_hz", 0.0, 10.0);
    return o;
  }
};

struct ImuOptions {
  int rate_hz = 0;
  int min_rate_hz = 0;
  NoiseOptions noise;
  Eigen::Matrix4d T_body_imu = Eigen::Matrix4d::Identity();
  bool use_magnetometer = false;

  static ImuOptions Load(const ConfigNode& node) {
    ImuOptions o;
    o.rate_hz = node.GetInRange<int>("rate_hz", 100, 1000);
    o.min_rate_hz = node.GetInRange<int>("min_rate_hz", 1, 1000, 50);
    if (o.min_rate_hz > o.rate_hz) node.Fail("min_rate_hz", "must not exceed rate_hz");
    o.noise = NoiseOptions::Load(node.Child("noise"));
    o.T_body_imu = node.Get<Eigen::Matrix4d>("T_body_imu", Eigen::Matrix4d::Identity());
    o.use_magnetometer = node.Get<bool>("use_magnetometer", false);
    return o;
  }
};

struct LogOptions {
  std::string directory;
  Compression compression = Compression::kZstd;
  std::vector<std::string> topics;

  static LogOptions Load(const ConfigNode& node) {
    LogOptions o;
    o.directory = node.Get<std::string>("directory");
    o.compression = node.GetEnum<Compression>(
        "compression",
        {{"none", Compression::kNone}, {"lz4", Compression::kLz4}, {"zstd", Compression::kZstd}},
        Compression::kZstd);
    o.topics = node.Get<std::vector<std::string>>("topics", {});
    return o;
  }
};

struct RoverOptions {
  ImuOptions imu;
  LogOptions log;

  static RoverOptions LoadFile(const std::string& path) {
    const ConfigNode root = ConfigNode::LoadFile(path);
    RoverOptions o;
    o.imu = ImuOptions::Load(root.Child("imu"));
    o.log = LogOptions::Load(root.Child("log"));
    root.CheckNoUnknownKeysRecursive();
    return o;
  }
};

constexpr char kRoverYaml[] =
    "imu:\n"                                          // 1
    "  rate_hz: 400\n"                                // 2
    "  noise:\n"                                      // 3
    "    gyro_noise_density_rad_s_sqrt_hz: 1.7e-4\n"  // 4
    "    accel_noise_density_m_s2_sqrt_hz: 2.0e-3\n"  // 5
    "  T_body_imu: [1, 0, 0, 0.05,\n"                 // 6
    "               0, 1, 0, 0,\n"                    // 7
    "               0, 0, 1, -0.02,\n"                // 8
    "               0, 0, 0, 1]\n"                    // 9
    "log:\n"                                          // 10
    "  directory: /var/log/rover\n"                   // 11
    "  compression: lz4\n"                            // 12
    "  topics: [/imu, /odom]\n";                      // 13

TEST(ConfigOptionsExampleTest, LoadsAValidFile) {
  const TempYamlFile file(kRoverYaml);
  const RoverOptions o = RoverOptions::LoadFile(file.path());
  EXPECT_EQ(o.imu.rate_hz, 400);
  EXPECT_EQ(o.imu.min_rate_hz, 50);
  EXPECT_DOUBLE_EQ(o.imu.noise.gyro_noise_density_rad_s_sqrt_hz, 1.7e-4);
  EXPECT_DOUBLE_EQ(o.imu.T_body_imu(0, 3), 0.05);
  EXPECT_DOUBLE_EQ(o.imu.T_body_imu(2, 3), -0.02);
  EXPECT_FALSE(o.imu.use_magnetometer);
  EXPECT_EQ(o.log.compression, Compression::kLz4);
  EXPECT_THAT(o.log.topics, ::testing::ElementsAre("/imu", "/odom"));
}

TEST(ConfigOptionsExampleTest, TypoInOptionalKeyIsCaught) {
  // Misspelled on line 12: without the check, the default (zstd) would win
  // silently.
  std::string yaml = kRoverYaml;
  yaml.replace(yaml.find("compression: lz4"), 16, "compresion: lz4");
  const TempYamlFile file(yaml);
  EXPECT_EQ(ErrorOf([&] { RoverOptions::LoadFile(file.path()); }),
            file.path() + ":12: log.compresion: unknown key (did you mean \"compression\"?)");
}

TEST(ConfigOptionsExampleTest, CrossFieldValidation) {
  std::string yaml = kRoverYaml;
  yaml.replace(yaml.find("  rate_hz: 400\n"), 15, "  rate_hz: 400\n  min_rate_hz: 500\n");
  const TempYamlFile file(yaml);
  EXPECT_EQ(ErrorOf([&] { RoverOptions::LoadFile(file.path()); }),
            file.path() + ":3: imu.min_rate_hz: must not exceed rate_hz");
}

TEST(ConfigOptionsExampleTest, ErrorsDoNotMentionUnrelatedKeys) {
  std::string yaml = kRoverYaml;
  yaml.replace(yaml.find("1.7e-4"), 6, "-1e-4");
  const TempYamlFile file(yaml);
  const std::string error = ErrorOf([&] { RoverOptions::LoadFile(file.path()); });
  EXPECT_EQ(error, file.path() +
                       ":4: imu.noise.gyro_noise_density_rad_s_sqrt_hz: expected a number in "
                       "[0, 1], found -1e-4");
  EXPECT_THAT(error, Not(HasSubstr("unknown")));
}

}  // namespace
}  // namespace rover
