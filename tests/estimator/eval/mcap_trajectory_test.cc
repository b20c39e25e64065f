#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <random>

#include "core/log/mcap/mcap_writer.h"
#include "core/log/msgs/all_msgs.h"
#include "estimator/eval/eval_error.h"
#include "estimator/eval/mcap_trajectory.h"
#include "estimator/eval/trajectory_evaluation.h"
#include "estimator/eval/trajectory_io.h"
#include "tests/estimator/eval/eval_test_util.h"
#include "tests/support/temp_dir.h"

namespace rover::eval {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

std::span<const std::byte> AsBytes(std::string_view s) {
  return {reinterpret_cast<const std::byte*>(s.data()), s.size()};
}

template <typename T>
uint16_t AddChannel(log::McapWriter& writer, std::string_view topic) {
  using Traits = log::MessageTraits<T>;
  const uint16_t schema =
      writer.AddSchema(Traits::kName, log::kRos2MsgSchemaEncoding, AsBytes(Traits::Definition()));
  return writer.AddChannel(schema, topic, log::kCdrMessageEncoding);
}

template <typename T>
void Write(log::McapWriter& writer, uint16_t channel, Time t, const T& msg) {
  static uint32_t sequence = 0;
  const auto bytes = log::SerializeMessage(msg);
  const auto ns = static_cast<uint64_t>(t.nanoseconds());
  writer.WriteMessage(channel, sequence++, ns, ns, bytes);
}

log::geometry_msgs::Pose ToPose(const Eigen::Isometry3d& T) {
  log::geometry_msgs::Pose pose;
  pose.position = {T.translation().x(), T.translation().y(), T.translation().z()};
  const Eigen::Quaterniond q(T.linear());
  pose.orientation = {q.x(), q.y(), q.z(), q.w()};
  return pose;
}

std::array<double, 36> RowMajor(const Matrix6d& P) {
  std::array<double, 36> c{};
  for (int r = 0; r < 6; ++r) {
    for (int k = 0; k < 6; ++k) c[static_cast<std::size_t>(6 * r + k)] = P(r, k);
  }
  return c;
}

// A flight log of a random trajectory whose estimate switches frame twice:
// local/rover1/0 -> local/rover1/1 at sample 100, -> local/rover1/2 at 200.
class McapTrajectoryTest : public ::testing::Test {
 protected:
  void SetUp() override {
    truth_ = testing::RandomTrajectory(rng_, kSamples, 20'000'000);
    T_0_1_ = testing::RandomPose(rng_, 10.0);
    T_1_2_ = testing::RandomPose(rng_, 10.0);
    log::McapWriterOptions options;
    options.chunk_size_bytes = 20'000;
    log::McapWriter writer(options);
    writer.Open(path_);
    const uint16_t odometry = AddChannel<log::nav_msgs::Odometry>(writer, "/estimator/odometry");
    const uint16_t switches =
        AddChannel<log::geometry_msgs::TransformStamped>(writer, "/estimator/frame_switch");
    const uint16_t other =
        AddChannel<log::geometry_msgs::PoseWithCovarianceStamped>(writer, "/other/pose");
    const char* frames[] = {"local/rover1/0", "local/rover1/1", "local/rover1/2"};
    const Eigen::Isometry3d T_0_frame[] = {Eigen::Isometry3d::Identity(), T_0_1_, T_0_1_ * T_1_2_};
    for (int i = 0; i < kSamples; ++i) {
      const PoseSample& s = truth_[static_cast<std::size_t>(i)];
      const int frame = i < 100 ? 0 : (i < 200 ? 1 : 2);
      if (i == 100 || i == 200) {
        log::geometry_msgs::TransformStamped sw;
        sw.header.stamp = log::ToRosTime(s.stamp - Duration::Milliseconds(5));
        sw.header.frame_id = *log::FrameId::FromString(frames[frame - 1]);
        sw.child_frame_id = *log::FrameId::FromString(frames[frame]);
        const Eigen::Isometry3d T_old_new = frame == 1 ? T_0_1_ : T_1_2_;
        sw.transform.translation = {T_old_new.translation().x(), T_old_new.translation().y(),
                                    T_old_new.translation().z()};
        const Eigen::Quaterniond q(T_old_new.linear());
        sw.transform.rotation = {q.x(), q.y(), q.z(), q.w()};
        Write(writer, switches, s.stamp, sw);
      }
      const Eigen::Isometry3d T_frame_body = T_0_frame[frame].inverse() * s.T_world_body();
      const Matrix6d P_local = testing::RandomCovariance(rng_, 0.1, 0.01);
      covariance_local_.push_back(P_local);
      log::nav_msgs::Odometry msg;
      msg.header.stamp = log::ToRosTime(s.stamp);
      msg.header.frame_id = *log::FrameId::FromString(frames[frame]);
      msg.child_frame_id = "body";
      msg.pose.pose = ToPose(T_frame_body);
      msg.pose.covariance = RowMajor(P_local);
      const Eigen::Vector3d v_body = s.q_world_body.inverse() * *s.v_world_body_m_s;
      msg.twist.twist.linear = {v_body.x(), v_body.y(), v_body.z()};
      // Log time slightly after the stamp, as the filter publishes late.
      Write(writer, odometry, s.stamp + Duration::Milliseconds(3), msg);
      if (i % 10 == 0) {
        log::geometry_msgs::PoseWithCovarianceStamped p;
        p.header.stamp = msg.header.stamp;
        p.header.frame_id = "map";
        p.pose.pose = ToPose(s.T_world_body());
        Write(writer, other, s.stamp, p);
      }
    }
    writer.Close();
  }

  static constexpr int kSamples = 300;
  std::mt19937_64 rng_{99};
  rover::testing::TempDir dir_{"eval_mcap"};
  std::string path_ = dir_.File("flight.mcap").string();
  Trajectory truth_;
  Eigen::Isometry3d T_0_1_, T_1_2_;
  std::vector<Matrix6d> covariance_local_;
};

TEST_F(McapTrajectoryTest, ChainsTwoFrameSwitchesIntoTheFirstFrame) {
  const McapTrajectory m = ReadMcapTrajectory(path_);
  EXPECT_EQ(m.frame_id, "local/rover1/0");
  ASSERT_EQ(m.switches.size(), 2u);
  EXPECT_EQ(m.switches[1].old_frame_id, "local/rover1/1");
  EXPECT_EQ(m.switches[1].new_frame_id, "local/rover1/2");
  EXPECT_TRUE(m.damage.empty());
  ASSERT_EQ(m.trajectory.size(), static_cast<std::size_t>(kSamples));
  const Eigen::Matrix3d R_0_frame[] = {Eigen::Matrix3d::Identity(), T_0_1_.linear(),
                                       (T_0_1_ * T_1_2_).linear()};
  for (int i = 0; i < kSamples; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const PoseSample& got = m.trajectory[k];
    const PoseSample& want = truth_[k];
    EXPECT_EQ(got.stamp, want.stamp);
    EXPECT_NEAR((got.p_world_body - want.p_world_body).norm(), 0.0, 1e-9) << i;
    EXPECT_NEAR(got.q_world_body.angularDistance(want.q_world_body), 0.0, 1e-9) << i;
    ASSERT_TRUE(got.v_world_body_m_s.has_value());
    EXPECT_NEAR((*got.v_world_body_m_s - *want.v_world_body_m_s).norm(), 0.0, 1e-9) << i;
    // Position covariance rotated into the first frame, attitude (body side) unchanged.
    Matrix6d J = Matrix6d::Identity();
    J.topLeftCorner<3, 3>() = R_0_frame[i < 100 ? 0 : (i < 200 ? 1 : 2)];
    ASSERT_TRUE(got.covariance.has_value());
    EXPECT_LT((*got.covariance - J * covariance_local_[k] * J.transpose()).cwiseAbs().maxCoeff(),
              1e-12)
        << i;
  }
  // Without chaining the samples after the first switch would be off.
  McapTrajectoryOptions unchained;
  unchained.frame_switch_topic = "";
  const McapTrajectory raw = ReadMcapTrajectory(path_, unchained);
  EXPECT_GT((raw.trajectory[150].p_world_body - truth_[150].p_world_body).norm(), 1e-3);
}

TEST_F(McapTrajectoryTest, EvaluatesAgainstTruthWithNeesAndAutoDetection) {
  TrajectoryFormat format = TrajectoryFormat::kAuto;
  const Trajectory estimate = ReadTrajectory(path_, {}, &format);
  EXPECT_EQ(format, TrajectoryFormat::kMcap);
  EvaluationOptions options;
  options.alignment.method = AlignmentMethod::kNone;
  const TrajectoryEvaluation r = EvaluateTrajectory(estimate, truth_, options);
  EXPECT_LT(r.ate.position_m.max, 1e-9);
  ASSERT_TRUE(r.nees.has_value());
  EXPECT_EQ(r.nees->samples.size(), static_cast<std::size_t>(kSamples));
  EXPECT_LT(r.nees->mean_position, 1e-12);
}

TEST_F(McapTrajectoryTest, TopicOverrideReadsPoseWithCovarianceStamped) {
  TrajectoryReadOptions options;
  options.mcap.topic = "/other/pose";
  const Trajectory t = ReadTrajectory(path_, options);
  ASSERT_EQ(t.size(), 30u);
  EXPECT_NEAR((t[3].p_world_body - truth_[30].p_world_body).norm(), 0.0, 1e-9);
  EXPECT_FALSE(t.HasCovariance());  // all-zero covariance means "not filled"
}

TEST_F(McapTrajectoryTest, MissingTopicListsTheTopics) {
  McapTrajectoryOptions options;
  options.topic = "/nope";
  try {
    ReadMcapTrajectory(path_, options);
    FAIL() << "expected an EvalError";
  } catch (const EvalError& e) {
    EXPECT_THAT(e.what(),
                StartsWith(path_ + ": expected a channel on topic '/nope', found topics: "));
    EXPECT_THAT(e.what(), HasSubstr("/estimator/frame_switch, /estimator/odometry, /other/pose"));
  }
  options.topic = "/estimator/frame_switch";
  EXPECT_THROW(ReadMcapTrajectory(path_, options), EvalError);
}

TEST(McapTrajectoryErrorsTest, NonUnitQuaternionNamesTheMessage) {
  rover::testing::TempDir dir("eval_mcap");
  const std::string path = dir.File("bad.mcap").string();
  {
    log::McapWriter writer;
    writer.Open(path);
    const uint16_t odometry = AddChannel<log::nav_msgs::Odometry>(writer, "/estimator/odometry");
    log::nav_msgs::Odometry msg;
    msg.header.frame_id = "local/a";
    msg.header.stamp = {1, 0};
    Write(writer, odometry, Time::FromNanoseconds(1'000'000'000), msg);
    msg.header.frame_id = "local/b";
    msg.header.stamp = {2, 0};
    Write(writer, odometry, Time::FromNanoseconds(2'000'000'000), msg);
    msg.pose.pose.orientation.w = 3.0;
    msg.header.stamp = {3, 0};
    Write(writer, odometry, Time::FromNanoseconds(3'000'000'000), msg);
    writer.Close();
  }
  try {
    ReadMcapTrajectory(path);
    FAIL() << "expected an EvalError";
  } catch (const EvalError& e) {
    EXPECT_THAT(e.what(), StartsWith(path + ": message 3 on /estimator/odometry (log time "
                                            "3.000000000 s): expected a unit quaternion"));
  }
  // Not an MCAP file at all.
  const std::string text = dir.File("x.mcap").string();
  std::ofstream(text) << "hello\n";
  EXPECT_THROW(ReadMcapTrajectory(text), EvalError);
}

TEST(McapTrajectoryErrorsTest, UnknownFrameIdIsAnError) {
  rover::testing::TempDir dir("eval_mcap");
  const std::string path = dir.File("frames.mcap").string();
  {
    log::McapWriter writer;
    writer.Open(path);
    const uint16_t odometry = AddChannel<log::nav_msgs::Odometry>(writer, "/estimator/odometry");
    log::nav_msgs::Odometry msg;
    msg.header.frame_id = "local/a";
    msg.header.stamp = {1, 0};
    Write(writer, odometry, Time::FromNanoseconds(1'000'000'000), msg);
    msg.header.frame_id = "local/b";
    msg.header.stamp = {2, 0};
    Write(writer, odometry, Time::FromNanoseconds(2'000'000'000), msg);
    writer.Close();
  }
  try {
    ReadMcapTrajectory(path);
    FAIL() << "expected an EvalError";
  } catch (const EvalError& e) {
    EXPECT_THAT(e.what(), HasSubstr("message 2 on /estimator/odometry"));
    EXPECT_THAT(e.what(), HasSubstr("expected a frame id connected to 'local/a'"));
    EXPECT_THAT(e.what(), HasSubstr("found 'local/b'"));
  }
}

}  // namespace
}  // namespace rover::eval
