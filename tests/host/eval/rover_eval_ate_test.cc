#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <random>
#include <sstream>

#include "core/geometry/so3.h"
#include "core/geometry/yaw.h"
#include "core/log/mcap/mcap_writer.h"
#include "core/log/msgs/all_msgs.h"
#include "estimator/eval/text_table_reader.h"
#include "estimator/eval/trajectory_io.h"
#include "host/eval/ate_command.h"
#include "tests/support/temp_dir.h"

namespace rover::host::eval {
namespace {

namespace ev = rover::eval;
using ::testing::HasSubstr;
using ::testing::StartsWith;

std::string SharedData(const std::string& relative) {
  const char* shared = std::getenv("ROVER_SHARED_DIR");
  if (shared == nullptr) return "(ROVER_SHARED_DIR not set; run through ctest)/" + relative;
  return std::string(shared) + "/data/euroc_v1_01_micro/" + relative;
}

const std::string kGroundTruth = "groundtruth/V1_01_easy_openvins.csv";

// The fields of the RESULT line (the last line of the report).
std::map<std::string, std::string> ResultFields(const std::string& report) {
  std::istringstream in(report);
  std::string line, last;
  while (std::getline(in, line)) {
    if (!line.empty()) last = line;
  }
  std::map<std::string, std::string> fields;
  std::istringstream words(last);
  std::string word;
  words >> word;
  if (word != "RESULT") return fields;
  while (words >> word) {
    const auto eq = word.find('=');
    fields[word.substr(0, eq)] = word.substr(eq + 1);
  }
  return fields;
}

double Field(const std::map<std::string, std::string>& fields, const std::string& key) {
  const auto it = fields.find(key);
  return it == fields.end() ? -1.0 : std::stod(it->second);
}

// Odometry-style dead reckoning on the real EuRoC data, as a stand-in for an
// estimator: the attitude integrates the real IMU gyro (200 Hz) minus the
// ground-truth gyro bias, and the position integrates the ground-truth
// velocity expressed in the body frame (what a wheel or visual odometry
// measures) rotated by that attitude (trapezoid, 20 Hz), from the first
// ground-truth pose. Attitude drift turns into position drift as it would in
// a real odometry.
ev::Trajectory DeadReckoning(const ev::Trajectory& truth) {
  // Gyro biases: columns bwx, bwy, bwz (11-13) of the ground-truth CSV.
  std::vector<Eigen::Vector3d> bias;
  {
    ev::TextTableReader csv(SharedData(kGroundTruth), ev::TextTableReader::Separator::kComma);
    std::vector<std::string_view> c;
    while (csv.Next(&c))
      bias.emplace_back(csv.Double(c[11], "bwx"), csv.Double(c[12], "bwy"),
                        csv.Double(c[13], "bwz"));
  }
  std::vector<std::pair<Time, Eigen::Vector3d>> gyro;
  {
    ev::TextTableReader csv(SharedData("mav0/imu0/data.csv"),
                            ev::TextTableReader::Separator::kComma);
    std::vector<std::string_view> c;
    while (csv.Next(&c)) {
      gyro.emplace_back(
          csv.Nanoseconds(c[0], "t"),
          Eigen::Vector3d(csv.Double(c[1], "wx"), csv.Double(c[2], "wy"), csv.Double(c[3], "wz")));
    }
  }
  EXPECT_EQ(bias.size(), truth.size());
  ev::Trajectory estimate;
  ev::PoseSample s = truth[0];
  s.v_world_body_m_s.reset();
  estimate.Append(s);
  std::size_t j = 0;
  for (std::size_t k = 1; k < truth.size(); ++k) {
    const Time t0 = truth[k - 1].stamp, t1 = truth[k].stamp;
    const Eigen::Quaterniond q0 = s.q_world_body;
    while (j + 1 < gyro.size() && gyro[j + 1].first <= t0) ++j;
    for (std::size_t i = j; i + 1 < gyro.size() && gyro[i].first < t1; ++i) {
      const Time a = std::max(gyro[i].first, t0), b = std::min(gyro[i + 1].first, t1);
      if (b <= a) continue;
      s.q_world_body = (s.q_world_body * QuaternionFromRotationVector(
                                             (gyro[i].second - bias[k - 1]) * (b - a).ToSeconds()))
                           .normalized();
    }
    const Eigen::Vector3d v0_body =
        truth[k - 1].q_world_body.inverse() * *truth[k - 1].v_world_body_m_s;
    const Eigen::Vector3d v1_body = truth[k].q_world_body.inverse() * *truth[k].v_world_body_m_s;
    s.p_world_body += 0.5 * (t1 - t0).ToSeconds() * (q0 * v0_body + s.q_world_body * v1_body);
    s.stamp = t1;
    estimate.Append(s);
  }
  return estimate;
}

class RoverEvalAteTest : public ::testing::Test {
 protected:
  void SetUp() override {
    options_.truth_path = SharedData(kGroundTruth);
    truth_ = ev::ReadTrajectory(options_.truth_path);
  }
  int Run() {
    out_.str("");
    err_.str("");
    return RunAte(options_, out_, err_);
  }
  rover::testing::TempDir dir_{"rover_eval"};
  AteCommandOptions options_;
  ev::Trajectory truth_;
  std::ostringstream out_, err_;
};

TEST_F(RoverEvalAteTest, DeadReckoningOnEurocHasASmallAlignedError) {
  const ev::Trajectory estimate = DeadReckoning(truth_);
  options_.estimate_path = dir_.File("dead_reckoning.txt").string();
  ev::WriteTrajectory(estimate, options_.estimate_path, ev::TrajectoryFormat::kTum);

  options_.evaluation.alignment.method = ev::AlignmentMethod::kFourDof;
  ASSERT_EQ(Run(), kExitOk) << err_.str();
  const std::string report = out_.str();
  EXPECT_THAT(report, HasSubstr("(tum, 2895 poses"));
  EXPECT_THAT(report, HasSubstr("(openvins, 2895 poses"));
  EXPECT_THAT(report, HasSubstr("Absolute trajectory error"));
  EXPECT_THAT(report, HasSubstr("Relative pose error per segment length"));
  EXPECT_THAT(report, ::testing::Not(HasSubstr("NEES")));
  const auto fields = ResultFields(report);
  EXPECT_EQ(fields.at("poses"), "2895");
  EXPECT_NEAR(Field(fields, "distance_m"), 58.35, 0.01);
  // Measured: ATE 0.019 m RMSE, 0.57 deg; RPE at 10 m 0.13 %, 0.033 deg/m. The
  // lower bounds make sure the estimate really is a different trajectory.
  EXPECT_GT(Field(fields, "ate_rmse_m"), 0.005);
  EXPECT_LT(Field(fields, "ate_rmse_m"), 0.05);
  EXPECT_GT(Field(fields, "ate_rot_rmse_deg"), 0.2);
  EXPECT_LT(Field(fields, "ate_rot_rmse_deg"), 1.5);
  EXPECT_LT(Field(fields, "final_err_pct"), 0.2);
  EXPECT_GT(Field(fields, "rpe_trans_pct"), 0.02);
  EXPECT_LT(Field(fields, "rpe_trans_pct"), 0.5);
  EXPECT_LT(Field(fields, "rpe_rot_deg_per_m"), 0.1);

  // The 4-DoF fit is at least as good as none and no better than SE(3)'s,
  // which has two more degrees of freedom.
  options_.evaluation.alignment.method = ev::AlignmentMethod::kNone;
  ASSERT_EQ(Run(), kExitOk) << err_.str();
  const double unaligned = Field(ResultFields(out_.str()), "ate_rmse_m");
  options_.evaluation.alignment.method = ev::AlignmentMethod::kSe3;
  ASSERT_EQ(Run(), kExitOk) << err_.str();
  const double se3 = Field(ResultFields(out_.str()), "ate_rmse_m");
  EXPECT_GE(unaligned, Field(fields, "ate_rmse_m"));
  EXPECT_LE(se3, Field(fields, "ate_rmse_m") + 1e-12);
}

TEST_F(RoverEvalAteTest, RigidlyMovedCopyOfTheGroundTruthAlignsExactly) {
  // The ground truth seen from another gravity-aligned frame, exported as a
  // EuRoC CSV with stamps 256 ns late (as some EuRoC files are).
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Rz(2.0);
  T.translation() = Eigen::Vector3d(10.0, -4.0, 0.5);
  ev::Trajectory moved = truth_.Transformed(T);
  for (ev::PoseSample& s : moved.mutable_samples()) s.stamp += Duration::Nanoseconds(256);
  options_.estimate_path = dir_.File("moved.csv").string();
  ev::WriteTrajectory(moved, options_.estimate_path, ev::TrajectoryFormat::kEuroc);

  for (const ev::AlignmentMethod method :
       {ev::AlignmentMethod::kFourDof, ev::AlignmentMethod::kSe3, ev::AlignmentMethod::kSim3}) {
    options_.evaluation.alignment.method = method;
    ASSERT_EQ(Run(), kExitOk) << err_.str();
    const auto fields = ResultFields(out_.str());
    EXPECT_EQ(fields.at("poses"), "2895");
    EXPECT_LT(Field(fields, "ate_rmse_m"), 1e-6) << ev::ToString(method);
    EXPECT_LT(Field(fields, "ate_rot_rmse_deg"), 1e-5) << ev::ToString(method);
  }
  EXPECT_THAT(out_.str(), HasSubstr("(euroc, 2895 poses"));
  EXPECT_THAT(out_.str(), HasSubstr("scale 1.000000"));
  EXPECT_THAT(out_.str(), ::testing::Not(HasSubstr("poorly determined")));
  options_.evaluation.alignment.method = ev::AlignmentMethod::kNone;
  ASSERT_EQ(Run(), kExitOk) << err_.str();
  EXPECT_GT(Field(ResultFields(out_.str()), "ate_rmse_m"), 1.0);
}

TEST_F(RoverEvalAteTest, ResultLineKeepsEveryFieldWhenRpeCannotBeComputed) {
  // The image window of the micro excerpt: 4.7 s with the MAV standing still.
  ev::Trajectory still;
  for (const ev::PoseSample& s : truth_) {
    if (s.stamp.nanoseconds() >= 1403715273262142976 &&
        s.stamp.nanoseconds() <= 1403715277962142976) {
      still.Append(s);
    }
  }
  options_.estimate_path = dir_.File("still.txt").string();
  ev::WriteTrajectory(still, options_.estimate_path, ev::TrajectoryFormat::kTum);
  ASSERT_EQ(Run(), kExitOk) << err_.str();
  const auto fields = ResultFields(out_.str());
  for (const char* key : {"poses", "distance_m", "ate_rmse_m", "ate_rot_rmse_deg", "final_err_m",
                          "final_err_pct", "mean_err_pct", "rpe_trans_pct", "rpe_rot_deg_per_m"}) {
    EXPECT_EQ(fields.count(key), 1u) << key;
  }
  EXPECT_EQ(fields.at("poses"), "95");
  EXPECT_EQ(fields.at("rpe_trans_pct"), "nan");
  EXPECT_EQ(fields.at("rpe_rot_deg_per_m"), "nan");
  EXPECT_LT(Field(fields, "distance_m"), 0.1);
  EXPECT_THAT(out_.str(), HasSubstr("shorter than every segment length"));
  EXPECT_THAT(out_.str(), HasSubstr("the alignment rotation is poorly determined"));
}

TEST_F(RoverEvalAteTest, InputProblemsAreClearErrors) {
  options_.estimate_path = dir_.File("missing.txt").string();
  EXPECT_EQ(Run(), kExitBadInput);
  EXPECT_THAT(err_.str(),
              StartsWith("rover-eval ate: " + options_.estimate_path + ": cannot open"));

  options_.estimate_path = dir_.File("bad.txt").string();
  std::ofstream(options_.estimate_path) << "# t x y z qx qy qz qw\n1 0 0 0 0 0 0 1\n2 0 0\n";
  EXPECT_EQ(Run(), kExitBadInput);
  EXPECT_THAT(err_.str(), HasSubstr(options_.estimate_path + ":3: expected 8 columns"));

  // Stamps of a different clock: no overlap.
  options_.estimate_path = dir_.File("other_clock.txt").string();
  std::ofstream(options_.estimate_path) << "1 0 0 0 0 0 0 1\n2 1 0 0 0 0 0 1\n3 2 0 0 0 0 0 1\n";
  EXPECT_EQ(Run(), kExitBadInput);
  EXPECT_THAT(err_.str(), HasSubstr("no estimate pose could be associated"));
  EXPECT_THAT(err_.str(), HasSubstr("check the time offset"));
  EXPECT_TRUE(out_.str().find("RESULT") == std::string::npos);
}

TEST_F(RoverEvalAteTest, FlightLogEstimateGetsANeesSummary) {
  // Odometry for the first 200 ground-truth poses, with a covariance that
  // matches errors of a known size.
  const std::string path = dir_.File("flight.mcap").string();
  {
    log::McapWriter writer;
    writer.Open(path);
    using Traits = log::MessageTraits<log::nav_msgs::Odometry>;
    const std::string_view definition = Traits::Definition();
    const uint16_t schema = writer.AddSchema(
        Traits::kName, log::kRos2MsgSchemaEncoding,
        {reinterpret_cast<const std::byte*>(definition.data()), definition.size()});
    const uint16_t channel =
        writer.AddChannel(schema, "/estimator/odometry", log::kCdrMessageEncoding);
    std::mt19937_64 rng(5);
    std::normal_distribution<double> noise(0.0, 0.05);
    for (std::size_t i = 0; i < 200; ++i) {
      const ev::PoseSample& s = truth_[i];
      log::nav_msgs::Odometry msg;
      msg.header.stamp = log::ToRosTime(s.stamp);
      msg.header.frame_id = "local/rover1/0";
      msg.pose.pose.position = {s.p_world_body.x() + noise(rng), s.p_world_body.y() + noise(rng),
                                s.p_world_body.z() + noise(rng)};
      msg.pose.pose.orientation = {s.q_world_body.x(), s.q_world_body.y(), s.q_world_body.z(),
                                   s.q_world_body.w()};
      for (std::size_t d = 0; d < 6; ++d) msg.pose.covariance[7 * d] = d < 3 ? 0.0025 : 1e-4;
      const auto bytes = log::SerializeMessage(msg);
      const auto t = static_cast<uint64_t>(s.stamp.nanoseconds());
      writer.WriteMessage(channel, static_cast<uint32_t>(i), t, t, bytes);
    }
    writer.Close();
  }
  options_.estimate_path = path;
  options_.evaluation.alignment.method = ev::AlignmentMethod::kNone;
  ASSERT_EQ(Run(), kExitOk) << err_.str();
  EXPECT_THAT(out_.str(), HasSubstr("(mcap, 200 poses"));
  EXPECT_THAT(out_.str(), HasSubstr("NEES (200 poses with covariance)"));
  EXPECT_NEAR(Field(ResultFields(out_.str()), "ate_rmse_m"), 0.05 * std::sqrt(3.0), 0.01);
}

TEST(RoverEvalCommandLineTest, AteSubcommandParsesItsOptions) {
  CLI::App app;
  const Subcommand ate = AddAteCommand(app);
  const std::string truth = SharedData(kGroundTruth);
  EXPECT_THROW(app.parse("ate --est " + truth + " --gt " + truth + " --align 5dof"),
               CLI::ValidationError);
  CLI::App app2;
  const Subcommand ate2 = AddAteCommand(app2);
  app2.parse("ate --est " + truth + " --gt " + truth +
             " --align 4dof --segments 1,2.5 --max-gap-s 0.06 --offset-s 0 --gt-format openvins");
  ASSERT_TRUE(ate2.app->parsed());
  ::testing::internal::CaptureStdout();
  const int status = ate2.run();
  const std::string report = ::testing::internal::GetCapturedStdout();
  EXPECT_EQ(status, kExitOk);
  EXPECT_THAT(report, HasSubstr("alignment:    4dof"));
  EXPECT_THAT(report, HasSubstr("   2.5 *"));
  EXPECT_THAT(report, HasSubstr("gaps > 0.06 s"));
  (void)ate;
}

}  // namespace
}  // namespace rover::host::eval
