#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <random>

#include "estimator/eval/csv_trajectory.h"
#include "estimator/eval/eval_error.h"
#include "estimator/eval/number_format.h"
#include "estimator/eval/text_table_reader.h"
#include "estimator/eval/trajectory_io.h"
#include "estimator/eval/tum_trajectory.h"
#include "tests/estimator/eval/eval_test_util.h"
#include "tests/support/temp_dir.h"

namespace rover::eval {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

std::string ReadError(const std::string& path, TrajectoryFormat format = TrajectoryFormat::kAuto) {
  try {
    TrajectoryReadOptions options;
    options.format = format;
    ReadTrajectory(path, options);
  } catch (const EvalError& e) {
    return e.what();
  }
  return "(no error)";
}

void WriteText(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

class TrajectoryIoTest : public ::testing::Test {
 protected:
  std::string File(const char* name) const { return dir_.File(name).string(); }
  rover::testing::TempDir dir_{"eval_io"};
  std::mt19937_64 rng_{42};
};

void ExpectSamePoses(const Trajectory& a, const Trajectory& b, bool velocity) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].stamp, b[i].stamp) << i;
    // Written at full precision: exact equality.
    EXPECT_EQ(a[i].p_world_body, b[i].p_world_body) << i;
    EXPECT_EQ(a[i].q_world_body.coeffs(), b[i].q_world_body.coeffs()) << i;
    if (velocity) {
      ASSERT_TRUE(b[i].v_world_body_m_s.has_value());
      EXPECT_EQ(*a[i].v_world_body_m_s, *b[i].v_world_body_m_s) << i;
    }
  }
}

TEST_F(TrajectoryIoTest, TumRoundTripIsExact) {
  // Stamps of a realistic epoch with odd nanoseconds (a double would lose them).
  Trajectory t = testing::RandomTrajectory(rng_, 200, 5'000'001, 1403715273262142976);
  const std::string path = File("t.txt");
  WriteTumTrajectory(t, path);
  TrajectoryFormat format = TrajectoryFormat::kAuto;
  const Trajectory back = ReadTrajectory(path, {}, &format);
  EXPECT_EQ(format, TrajectoryFormat::kTum);
  ExpectSamePoses(t, back, /*velocity=*/false);
  EXPECT_EQ(back.source(), path);
}

TEST_F(TrajectoryIoTest, EurocRoundTripIsExactIncludingVelocity) {
  Trajectory t = testing::RandomTrajectory(rng_, 100, 5'000'001, 1403715273262142976);
  const std::string path = File("t.csv");
  WriteTrajectory(t, path, TrajectoryFormat::kEuroc);
  TrajectoryFormat format = TrajectoryFormat::kAuto;
  const Trajectory back = ReadTrajectory(path, {}, &format);
  EXPECT_EQ(format, TrajectoryFormat::kEuroc);
  ExpectSamePoses(t, back, /*velocity=*/true);
}

TEST_F(TrajectoryIoTest, EurocGroundTruthLayoutReadsWFirstAndVelocity) {
  const std::string path = File("data.csv");
  WriteText(path,
            "#timestamp [ns],p_RS_R_x [m],p_RS_R_y [m],p_RS_R_z [m],q_RS_w [],q_RS_x [],"
            "q_RS_y [],q_RS_z [],v_RS_R_x [m s^-1],v_RS_R_y [m s^-1],v_RS_R_z [m s^-1],"
            "b_w_RS_S_x [rad s^-1],b_w_RS_S_y [rad s^-1],b_w_RS_S_z [rad s^-1],"
            "b_a_RS_S_x [m s^-2],b_a_RS_S_y [m s^-2],b_a_RS_S_z [m s^-2]\n"
            "1403715273262142976,1,2,3,0,1,0,0,0.5,0.25,-1,0,0,0,0,0,0\n"
            "1403715273267142976,1.5,2,3,0,0,1,0,0.5,0.25,-1,0,0,0,0,0,0\n");
  const Trajectory t = ReadTrajectory(path);
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t[0].stamp.nanoseconds(), 1403715273262142976);
  EXPECT_EQ(t[0].p_world_body, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(t[0].q_world_body.coeffs(), Eigen::Vector4d(1, 0, 0, 0));  // x = 1 (w first in file)
  EXPECT_EQ(t[1].q_world_body.coeffs(), Eigen::Vector4d(0, 1, 0, 0));
  ASSERT_TRUE(t[1].v_world_body_m_s.has_value());
  EXPECT_EQ(*t[1].v_world_body_m_s, Eigen::Vector3d(0.5, 0.25, -1));
}

TEST_F(TrajectoryIoTest, OpenVinsHeaderSelectsUnitAndQuaternionOrder) {
  const std::string path = File("ov.csv");
  // Seconds and x, y, z, w order, as the header says.
  WriteText(path,
            "# timestamp(s),tx,ty,tz,qx,qy,qz,qw\n"
            "1403715273.262142976,1,2,3,0,0,1,0\n"
            "1403715273.3,1,2,4,0,0,0,1\n");
  TrajectoryFormat format = TrajectoryFormat::kAuto;
  const Trajectory t = ReadTrajectory(path, {}, &format);
  EXPECT_EQ(format, TrajectoryFormat::kOpenVins);
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t[0].stamp.nanoseconds(), 1403715273262142976);
  EXPECT_EQ(t[1].stamp.nanoseconds(), 1403715273300000000);
  EXPECT_EQ(t[0].q_world_body.coeffs(), Eigen::Vector4d(0, 0, 1, 0));  // z = 1
  EXPECT_EQ(t[1].q_world_body.coeffs(), Eigen::Vector4d(0, 0, 0, 1));  // identity
  EXPECT_FALSE(t[0].v_world_body_m_s.has_value());
}

TEST_F(TrajectoryIoTest, SharedOpenVinsGroundTruthIsNanosecondsWithWFirst) {
  const char* shared = std::getenv("ROVER_SHARED_DIR");
  ASSERT_NE(shared, nullptr) << "ROVER_SHARED_DIR is set by rover_add_test";
  const std::string path =
      std::string(shared) + "/data/euroc_v1_01_micro/groundtruth/V1_01_easy_openvins.csv";
  TrajectoryFormat format = TrajectoryFormat::kAuto;
  const Trajectory t = ReadTrajectory(path, {}, &format);
  EXPECT_EQ(format, TrajectoryFormat::kOpenVins);
  ASSERT_EQ(t.size(), 2895u);
  // First row: 1403715273262142976,0.878895,2.1834,0.948427,0.069433,-0.824237,-0.106942,-0.551702
  EXPECT_EQ(t[0].stamp.nanoseconds(), 1403715273262142976);
  EXPECT_NEAR(t[0].p_world_body.x(), 0.878895, 1e-12);
  const double n = Eigen::Vector4d(0.069433, -0.824237, -0.106942, -0.551702).norm();
  EXPECT_NEAR(t[0].q_world_body.w(), 0.069433 / n, 1e-12);
  EXPECT_NEAR(t[0].q_world_body.x(), -0.824237 / n, 1e-12);
  ASSERT_TRUE(t[0].v_world_body_m_s.has_value());
  EXPECT_NEAR(t[0].v_world_body_m_s->x(), 0.00157587, 1e-12);
  EXPECT_EQ(t.samples().back().stamp.nanoseconds(), 1403715417962142976);
}

TEST_F(TrajectoryIoTest, TumErrorsNameFileAndLine) {
  const std::string path = File("bad.txt");
  WriteText(path, "# comment\n1.0 0 0 0 0 0 0 1\n2.0 0 0 0 0 0 0\n");
  EXPECT_EQ(ReadError(path),
            path + ":3: expected 8 columns (timestamp tx ty tz qx qy qz qw), found 7");

  WriteText(path, "1.0 0 0 0 0 0 0 1\n2.0 0 abc 0 0 0 0 1\n");
  EXPECT_EQ(ReadError(path), path + ":2: expected a finite number for ty, found 'abc'");

  WriteText(path, "1.0 0 0 0 0 0 0 1\n\n0.5 0 0 0 0 0 0 1\n");
  EXPECT_EQ(ReadError(path), path +
                                 ":3: expected the timestamp to increase, found 0.500000000 s "
                                 "after 1.000000000 s");

  WriteText(path, "1.0 0 0 0 0 0 0 2\n");
  EXPECT_EQ(ReadError(path),
            path + ":1: expected a unit quaternion (norm 1 +- 1e-3), found norm 2");

  WriteText(path, "1.0 0 0 0 0 0 0 1\n2.0 0 0 nan 0 0 0 1\n");
  EXPECT_THAT(ReadError(path), StartsWith(path + ":2: expected a finite number for tz"));
}

TEST_F(TrajectoryIoTest, CsvErrorsNameFileAndLine) {
  const std::string path = File("bad.csv");
  WriteText(path,
            "#timestamp [ns],p_RS_R_x [m],p_RS_R_y [m],p_RS_R_z [m],q_RS_w [],q_RS_x [],"
            "q_RS_y [],q_RS_z []\n100,0,0,0,1,0,0,0\n200,0,0,0,1,0,0\n");
  EXPECT_EQ(ReadError(path), path + ":3: expected at least 8 comma-separated columns, found 7");

  WriteText(path, "100,0,0,0,1,0,0,0\n200.5,0,0,0,1,0,0,0\n");
  EXPECT_EQ(ReadError(path, TrajectoryFormat::kEuroc),
            path + ":2: expected an integer for the timestamp [ns], found '200.5'");

  // Forcing the EuRoC layout on a file whose header says x, y, z, w.
  WriteText(path, "#t[ns],px,py,pz,qx,qy,qz,qw\n100,0,0,0,0,0,0,1\n");
  EXPECT_THAT(ReadError(path, TrajectoryFormat::kEuroc),
              StartsWith(path + ":1: expected EuRoC columns"));
  EXPECT_THAT(ReadError(path, TrajectoryFormat::kEuroc), HasSubstr("openvins"));
  EXPECT_EQ(ReadError(path), "(no error)");  // auto-detection reads it by its header

  // The OpenVINS reader needs the header.
  WriteText(path, "100,0,0,0,1,0,0,0\n");
  EXPECT_THAT(ReadError(path, TrajectoryFormat::kOpenVins),
              StartsWith(path + ":1: expected a header line naming the columns"));
  WriteText(path, "#time,px,py,pz,foo\n100,0,0,0,1\n");
  EXPECT_THAT(ReadError(path, TrajectoryFormat::kOpenVins),
              StartsWith(path + ":1: expected a header naming time, position and quaternion"));
}

TEST_F(TrajectoryIoTest, DetectionLooksAtTheDataNotOnlyTheComment) {
  const std::string path = File("tum.txt");
  WriteText(path, "# estimate, written by hand, 2 poses\n1.0 0 0 0 0 0 0 1\n2.0 1 0 0 0 0 0 1\n");
  EXPECT_EQ(DetectTrajectoryFormat(path), TrajectoryFormat::kTum);
  EXPECT_EQ(ReadTrajectory(path).size(), 2u);
  WriteText(path, "timestamp,px,py,pz,qw,qx,qy,qz\n5,0,0,0,1,0,0,0\n");  // header without '#'
  EXPECT_EQ(DetectTrajectoryFormat(path), TrajectoryFormat::kOpenVins);
  EXPECT_EQ(ReadTrajectory(path)[0].stamp.nanoseconds(), 5);
  WriteText(path, "5,0,0,0,1,0,0,0\n");
  EXPECT_EQ(DetectTrajectoryFormat(path), TrajectoryFormat::kEuroc);
  Time t;
  EXPECT_FALSE(ParseSecondsAsTime("9999999999.5", &t));  // beyond int64 nanoseconds
}

TEST_F(TrajectoryIoTest, MissingAndEmptyFilesAreClearErrors) {
  const std::string missing = File("nope.csv");
  EXPECT_THAT(ReadError(missing), StartsWith(missing + ": cannot open"));
  const std::string empty = File("empty.txt");
  WriteText(empty, "\n\n");
  EXPECT_THAT(ReadError(empty), HasSubstr("found an empty file"));
  WriteText(empty, "# only a comment\n");
  EXPECT_THAT(ReadError(empty), HasSubstr("expected trajectory rows, found none"));
}

TEST(NumberFormatTest, SecondsAreExactAndParseBack) {
  EXPECT_EQ(FormatSeconds(Time::FromNanoseconds(1403715273262142976)), "1403715273.262142976");
  EXPECT_EQ(FormatSeconds(Time::FromNanoseconds(-1)), "-0.000000001");
  Time t;
  ASSERT_TRUE(ParseSecondsAsTime("1403715273.262142976", &t));
  EXPECT_EQ(t.nanoseconds(), 1403715273262142976);
  ASSERT_TRUE(ParseSecondsAsTime("-0.000000001", &t));
  EXPECT_EQ(t.nanoseconds(), -1);
  ASSERT_TRUE(ParseSecondsAsTime("1.0000000005", &t));  // rounds the tenth digit
  EXPECT_EQ(t.nanoseconds(), 1'000'000'001);
  ASSERT_TRUE(ParseSecondsAsTime("1.5e3", &t));
  EXPECT_EQ(t.nanoseconds(), 1'500'000'000'000);
  EXPECT_FALSE(ParseSecondsAsTime("1.2.3", &t));
  EXPECT_FALSE(ParseSecondsAsTime("", &t));
}

TEST(TrajectoryTest, ValidateNamesTheBadSample) {
  Trajectory t({}, "mine");
  PoseSample s;
  s.stamp = Time::FromNanoseconds(10);
  t.Append(s);
  s.stamp = Time::FromNanoseconds(10);
  t.Append(s);
  try {
    t.Validate();
    FAIL() << "expected an EvalError";
  } catch (const EvalError& e) {
    EXPECT_THAT(e.what(), StartsWith("mine: sample 1 "));
    EXPECT_THAT(e.what(), HasSubstr("expected stamps to increase"));
  }
  t.mutable_samples()[1].stamp = Time::FromNanoseconds(20);
  t.mutable_samples()[1].q_world_body = Eigen::Quaterniond(0.5, 0, 0, 0);
  EXPECT_THROW(t.Validate(), EvalError);
  t.mutable_samples()[1].q_world_body = Eigen::Quaterniond::Identity();
  EXPECT_NO_THROW(t.Validate());
}

}  // namespace
}  // namespace rover::eval
