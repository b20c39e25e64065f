// rover-eval vio: the evaluation math on synthetic inputs with
// known answers, the option and CAN readers, and the whole command on the
// real EuRoC V1_01 micro excerpt (ROVER_SHARED_DIR, a few seconds).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/config/config.h"
#include "core/geometry/so3.h"
#include "core/geometry/yaw.h"
#include "estimator/eval/csv_trajectory.h"
#include "estimator/eval/eval_error.h"
#include "host/eval/can_frames_csv.h"
#include "host/eval/vio_command.h"
#include "host/eval/vio_evaluation.h"
#include "host/eval/vio_report.h"
#include "tests/support/temp_dir.h"

namespace rover::host::eval {
namespace {

namespace ev = rover::eval;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

Time At(double seconds) { return Time::FromNanoseconds(static_cast<int64_t>(seconds * 1e9)); }

Eigen::Isometry3d Pose(const Eigen::Vector3d& p, const Eigen::Vector3d& rotation_vector) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = ExpSO3(rotation_vector);
  T.translation() = p;
  return T;
}

ev::PoseSample Sample(Time stamp, const Eigen::Isometry3d& T) {
  ev::PoseSample s;
  s.stamp = stamp;
  s.p_world_body = T.translation();
  s.q_world_body = Eigen::Quaterniond(T.linear()).normalized();
  return s;
}

void ExpectPoseNear(const Eigen::Isometry3d& actual, const Eigen::Isometry3d& expected) {
  EXPECT_LT((actual.translation() - expected.translation()).norm(), 1e-9);
  EXPECT_LT(LogSO3(Eigen::Matrix3d(actual.linear().transpose() * expected.linear())).norm(), 1e-9);
}

std::string WriteFile(const testing::TempDir& dir, const std::string& name,
                      const std::string& text) {
  const std::string path = dir.File(name).string();
  std::ofstream(path) << text;
  return path;
}

// ---------------------------------------------------------------- VoChain

TEST(VoChainTest, OneChainKeepsTheVoPoses) {
  VoChain chain;
  const Eigen::Isometry3d T1 = Pose({1.0, 0.2, 0.0}, {0.0, 0.0, 0.3});
  EXPECT_TRUE(chain.Add(At(1.0), Eigen::Isometry3d::Identity(), true));
  EXPECT_TRUE(chain.Add(At(1.1), T1, false));
  ASSERT_EQ(chain.trajectory().size(), 2u);
  ExpectPoseNear(chain.trajectory()[1].T_world_body(), T1);
  EXPECT_EQ(chain.restarts(), 0);
}

TEST(VoChainTest, RestartedChainContinuesFromThePreviousChainsLastPose) {
  VoChain chain;
  // First chain: ends 1 m ahead, turned 90 deg left.
  const Eigen::Isometry3d end_a = Pose({1.0, 0.0, 0.0}, {0.0, 0.0, std::numbers::pi / 2});
  chain.Add(At(1.0), Eigen::Isometry3d::Identity(), true);
  chain.Add(At(1.1), end_a, false);
  // The second chain restarts its own odometry frame at its first keyframe
  // (here not at identity, as a VO that keeps counting could do) and then
  // moves 1 m forward in its body frame.
  const Eigen::Isometry3d start_b = Pose({5.0, 5.0, 0.0}, {0.0, 0.2, 0.0});
  const Eigen::Isometry3d step = Pose({1.0, 0.0, 0.0}, {0.0, 0.0, 0.0});
  chain.Add(At(1.3), start_b, true);
  chain.Add(At(1.4), start_b * step, false);
  ASSERT_EQ(chain.trajectory().size(), 4u);
  EXPECT_EQ(chain.restarts(), 1);
  ExpectPoseNear(chain.trajectory()[2].T_world_body(), end_a);
  // Forward along the turned heading: from (1, 0, 0) to (1, 1, 0).
  ExpectPoseNear(chain.trajectory()[3].T_world_body(), end_a * step);
  EXPECT_LT((chain.trajectory()[3].p_world_body - Eigen::Vector3d(1.0, 1.0, 0.0)).norm(), 1e-12);
}

TEST(VoChainTest, IgnoresFramesNotAfterTheLastOne) {
  VoChain chain;
  chain.Add(At(2.0), Eigen::Isometry3d::Identity(), true);
  EXPECT_FALSE(chain.Add(At(2.0), Pose({1.0, 0.0, 0.0}, {0.0, 0.0, 0.0}), false));
  EXPECT_FALSE(chain.Add(At(1.0), Pose({1.0, 0.0, 0.0}, {0.0, 0.0, 0.0}), true));
  EXPECT_EQ(chain.trajectory().size(), 1u);
  EXPECT_EQ(chain.restarts(), 0);
}

// ------------------------------------------------------ Delta-pose NEES

// Ground truth: a curving 3-D path sampled every 50 ms for 10 s.
ev::Trajectory CurvedTruth() {
  ev::Trajectory truth;
  for (int i = 0; i <= 200; ++i) {
    const double t = 0.05 * i;
    truth.Append(Sample(At(100.0 + t), Pose({std::sin(0.3 * t) * 4.0, 0.5 * t, 0.1 * t * t},
                                            {0.1 * std::sin(t), 0.05 * t, 0.2 * t})));
  }
  return truth;
}

// The measurement of the true relative pose with noise n = [n_p; n_theta]
// in the filter's convention.
estimator::RelativePoseMeasurement Measure(const ev::Trajectory& truth, Time from, Time to,
                                           const Vector6d& n, const Matrix6d& covariance) {
  const Eigen::Isometry3d T_from =
      ev::PoseAt(truth, from, Duration::Milliseconds(100))->T_world_body();
  const Eigen::Isometry3d T_to = ev::PoseAt(truth, to, Duration::Milliseconds(100))->T_world_body();
  const Eigen::Isometry3d T_true = T_from.inverse() * T_to;
  estimator::RelativePoseMeasurement m;
  m.stamp = to + Duration::Milliseconds(100);
  m.from_stamp = from;
  m.to_stamp = to;
  m.p_from_to = T_true.translation() + n.head<3>();
  m.q_from_to = Eigen::Quaterniond(T_true.linear() * ExpSO3(n.tail<3>())).normalized();
  m.covariance = covariance;
  return m;
}

TEST(DeltaPoseNeesTest, KnownErrorGivesItsNees) {
  const ev::Trajectory truth = CurvedTruth();
  Vector6d sigma, n;
  sigma << 0.01, 0.02, 0.04, 0.001, 0.002, 0.004;
  n << 0.01, -0.04, 0.04, 0.002, 0.0, -0.004;  // 1, 2, 1 and 2, 0, 1 sigmas
  const Matrix6d covariance = sigma.cwiseProduct(sigma).asDiagonal();
  std::vector<estimator::RelativePoseMeasurement> m = {
      Measure(truth, At(101.0), At(102.5), n, covariance),
      // Outside the ground truth: counted, not evaluated.
      Measure(truth, At(109.0), At(109.5), n, covariance)};
  m[1].to_stamp = At(111.0);

  const DeltaPoseNees r = ComputeDeltaPoseNees(m, truth, Duration::Milliseconds(100));
  EXPECT_EQ(r.measurements, 2u);
  EXPECT_EQ(r.without_truth, 1u);
  ASSERT_EQ(r.nees.samples.size(), 1u);
  EXPECT_NEAR(r.nees.mean_position, 1.0 + 4.0 + 1.0, 1e-6);
  EXPECT_NEAR(r.nees.mean_attitude, 4.0 + 0.0 + 1.0, 1e-6);
  EXPECT_NEAR(r.nees.mean_pose, 11.0, 1e-6);
  EXPECT_NEAR(r.bounds_6dof.lower, rover::stats::Chi2Quantile(6, 0.025), 1e-9);
  EXPECT_NEAR(r.bounds_6dof.upper, rover::stats::Chi2Quantile(6, 0.975), 1e-9);
  EXPECT_NEAR(r.bounds_3dof.upper, rover::stats::Chi2Quantile(3, 0.975), 1e-9);
  EXPECT_TRUE(r.pose_inside);  // 11 < 14.45
}

TEST(DeltaPoseNeesTest, NoiseDrawnFromTheCovarianceIsConsistent) {
  // A full (correlated) covariance and sizeable rotations: a wrong side of the
  // rotation noise or a transposed block would move the mean far from 6.
  const ev::Trajectory truth = CurvedTruth();
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  Matrix6d A;
  for (int i = 0; i < 36; ++i) A(i / 6, i % 6) = 0.02 * normal(rng);
  const Matrix6d covariance = A * A.transpose() + 1e-6 * Matrix6d::Identity();
  const Matrix6d L = covariance.llt().matrixL();
  std::vector<estimator::RelativePoseMeasurement> m;
  constexpr int kDraws = 2000;
  for (int i = 0; i < kDraws; ++i) {
    Vector6d z;
    for (int k = 0; k < 6; ++k) z(k) = normal(rng);
    const double from_s = 100.0 + 0.004 * (i % 1000);
    m.push_back(Measure(truth, At(from_s), At(from_s + 3.0), L * z, covariance));
  }
  const DeltaPoseNees r = ComputeDeltaPoseNees(m, truth, Duration::Milliseconds(100));
  ASSERT_EQ(r.nees.samples.size(), static_cast<std::size_t>(kDraws));
  EXPECT_TRUE(r.pose_inside) << r.nees.mean_pose << " outside [" << r.bounds_6dof.lower << ", "
                             << r.bounds_6dof.upper << "]";
  EXPECT_NEAR(r.nees.mean_position, 3.0, 0.25);
  EXPECT_NEAR(r.nees.mean_attitude, 3.0, 0.25);
}

TEST(DeltaPoseNeesTest, NoMeasurementsGiveNanBounds) {
  const DeltaPoseNees r = ComputeDeltaPoseNees({}, CurvedTruth(), Duration::Milliseconds(100));
  EXPECT_TRUE(std::isnan(r.nees.mean_pose));
  EXPECT_TRUE(std::isnan(r.bounds_6dof.lower));
  EXPECT_FALSE(r.pose_inside);
}

// ------------------------------------------------------------------ RPE

// A straight drive of `length_m` along x; the estimate over-reads distance by
// 2 % (scale error), so every segment has a 2 % translation error.
ev::RpeResult StraightDriveRpe(double length_m) {
  std::vector<ev::AssociatedPose> poses;
  for (int i = 0; i * 0.1 <= length_m + 1e-9; ++i) {
    ev::AssociatedPose a;
    a.stamp = At(i * 0.1);
    a.T_world_body_truth = Pose({i * 0.1, 0.0, 0.0}, Eigen::Vector3d::Zero());
    a.T_world_body_estimate = Pose({i * 0.1 * 1.02, 0.0, 0.0}, Eigen::Vector3d::Zero());
    poses.push_back(a);
  }
  ev::RpeOptions options;
  options.segment_lengths_m = {1.0, 5.0, 10.0, 20.0, 50.0};
  return ev::ComputeRpe(poses, options);
}

TEST(QuoteRpeTest, QuotesTenMetreSegmentsWhenTheyFit) {
  const RpeQuote q = QuoteRpe(StraightDriveRpe(25.0), 25.0);
  EXPECT_DOUBLE_EQ(q.length_m, 10.0);
  EXPECT_NEAR(q.translation_pct, 2.0, 0.01);  // segments end at the first pose >= L
  EXPECT_NEAR(q.rotation_deg_per_m, 0.0, 1e-9);
  EXPECT_GT(q.segments, 0u);
  EXPECT_THAT(q.note, HasSubstr("10 m segments"));
}

TEST(QuoteRpeTest, FallsBackToTheLongestLengthThatFits) {
  const RpeQuote q = QuoteRpe(StraightDriveRpe(7.0), 7.0);
  EXPECT_DOUBLE_EQ(q.length_m, 5.0);
  EXPECT_NEAR(q.translation_pct, 2.0, 0.01);  // segments end at the first pose >= L
  EXPECT_THAT(q.note, HasSubstr("too short for 10 m"));
}

TEST(QuoteRpeTest, NanWhenNoLengthFits) {
  const RpeQuote q = QuoteRpe(StraightDriveRpe(0.5), 0.5);
  EXPECT_TRUE(std::isnan(q.length_m));
  EXPECT_TRUE(std::isnan(q.translation_pct));
  EXPECT_TRUE(std::isnan(q.rotation_deg_per_m));
  EXPECT_THAT(q.note, HasSubstr("no RPE"));
}

// ------------------------------------------------- alignment at the start

// The truth along a turning, climbing path, and the estimate: the truth seen
// from another frame G, except that the last pose drifted by (0.3, 0.4, 0) m.
std::vector<ev::AssociatedPose> DriftedPoses(const Eigen::Isometry3d& G) {
  std::vector<ev::AssociatedPose> poses;
  for (int i = 0; i < 5; ++i) {
    ev::AssociatedPose a;
    a.stamp = At(i);
    a.T_world_body_truth = Pose({1.0 * i, 0.5 * i, 0.1 * i}, {0.05, -0.02, 0.3 * i});
    Eigen::Isometry3d drifted = a.T_world_body_truth;
    if (i == 4) drifted.translation() += Eigen::Vector3d(0.3, 0.4, 0.0);
    a.T_world_body_estimate = G.inverse() * drifted;
    poses.push_back(a);
  }
  return poses;
}

TEST(AlignedAtStartTest, FourDofAlignsYawAndTranslationAtTheFirstPose) {
  // Another gravity-aligned frame: yaw 30 deg and an offset.
  const Eigen::Isometry3d G = Pose({5.0, -2.0, 1.0}, {0.0, 0.0, std::numbers::pi / 6});
  const std::vector<ev::AssociatedPose> poses = DriftedPoses(G);
  const ev::Alignment a = AlignAtPose(poses.front(), ev::AlignmentMethod::kFourDof);
  EXPECT_EQ(a.method, ev::AlignmentMethod::kFourDof);
  ExpectPoseNear(a.T_truth_estimate, G);
  const StartAlignedErrors e = EvaluateAlignedAtStart(poses, ev::AlignmentMethod::kFourDof);
  EXPECT_NEAR(e.final_error_m, 0.5, 1e-9);
  EXPECT_NEAR(e.ate.position_m.max, 0.5, 1e-9);
  EXPECT_NEAR(e.ate.rotation_deg.max, 0.0, 1e-6);
  EXPECT_TRUE(std::isnan(EvaluateAlignedAtStart({}, ev::AlignmentMethod::kFourDof).final_error_m));
}

TEST(AlignedAtStartTest, Se3AlignsTheWholeFirstPose) {
  // A frame that is not gravity-aligned (a VO's odometry frame).
  const Eigen::Isometry3d G = Pose({5.0, -2.0, 1.0}, {0.4, -0.3, 1.0});
  const std::vector<ev::AssociatedPose> poses = DriftedPoses(G);
  ExpectPoseNear(AlignAtPose(poses.front(), ev::AlignmentMethod::kSe3).T_truth_estimate, G);
  EXPECT_NEAR(EvaluateAlignedAtStart(poses, ev::AlignmentMethod::kSe3).final_error_m, 0.5, 1e-9);
  // Yaw alone cannot undo that frame's roll and pitch.
  EXPECT_GT(EvaluateAlignedAtStart(poses, ev::AlignmentMethod::kFourDof).final_error_m, 0.6);
  EXPECT_THROW(AlignAtPose(poses.front(), ev::AlignmentMethod::kSim3), std::invalid_argument);
}

// ------------------------------------------------------------ CAN reader

TEST(ReadCanFramesCsvTest, ReadsTheSimulatorsFormat) {
  testing::TempDir dir;
  const std::string path = WriteFile(dir, "can.csv",
                                     "#timestamp [ns],id,dlc,data_hex\n"
                                     "1000000000000,0x080,0,\n"
                                     "1000000216075,0x181,8,ffffffff00000102\n");
  const std::vector<drivers::CanFrame> frames = ReadCanFramesCsv(path);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].id, 0x080u);
  EXPECT_EQ(frames[0].dlc, 0);
  EXPECT_EQ(frames[1].stamp.nanoseconds(), 1000000216075);
  EXPECT_EQ(frames[1].id, 0x181u);
  EXPECT_THAT(frames[1].data, ElementsAre(0xff, 0xff, 0xff, 0xff, 0x00, 0x00, 0x01, 0x02));
}

TEST(ReadCanFramesCsvTest, MalformedRowNamesFileAndLine) {
  testing::TempDir dir;
  const std::string path =
      WriteFile(dir, "can.csv", "#timestamp [ns],id,dlc,data_hex\n1000,0x181,8,ffff\n");
  try {
    ReadCanFramesCsv(path);
    FAIL() << "expected an EvalError";
  } catch (const ev::EvalError& e) {
    EXPECT_THAT(e.what(), HasSubstr("can.csv:2"));
    EXPECT_THAT(e.what(), HasSubstr("expected 16 hex digits"));
  }
}

// ------------------------------------------------- the command on EuRoC

std::string SharedEuroc() {
  const char* shared = std::getenv("ROVER_SHARED_DIR");
  return std::string(shared == nullptr ? "(ROVER_SHARED_DIR not set)" : shared) +
         "/data/euroc_v1_01_micro";
}

VioCommandOptions EurocOptions() {
  VioCommandOptions o;
  o.dataset_dir = SharedEuroc();
  o.truth_path = SharedEuroc() + "/groundtruth/V1_01_easy_openvins.csv";
  const char* source = std::getenv("ROVER_SOURCE_DIR");
  o.filter_config_path =
      std::string(source == nullptr ? "." : source) + "/host/eval/config/euroc_mav.yaml";
  return o;
}

// The RESULT line's keys in order and their values.
std::vector<std::pair<std::string, std::string>> ResultOf(const std::string& report) {
  std::istringstream in(report);
  std::string line, last;
  while (std::getline(in, line)) {
    if (!line.empty()) last = line;
  }
  std::vector<std::pair<std::string, std::string>> fields;
  std::istringstream words(last);
  std::string word;
  if (!(words >> word) || word != "RESULT") return fields;
  while (words >> word) {
    const auto eq = word.find('=');
    fields.emplace_back(word.substr(0, eq), eq == std::string::npos ? "" : word.substr(eq + 1));
  }
  return fields;
}

TEST(VioCommandTest, RunsOnTheEurocExcerpt) {
  testing::TempDir dir;
  VioCommandOptions options = EurocOptions();
  options.trajectory_out_path = dir.File("fused.csv").string();
  std::ostringstream err;
  const VioRun run = RunVioExperiment(options, err);
  std::ostringstream out;
  PrintVioReport(run, out);
  const std::string report = out.str();

  const auto fields = ResultOf(report);
  std::vector<std::string> keys;
  std::map<std::string, double> value;
  for (const auto& [k, v] : fields) {
    keys.push_back(k);
    value[k] = std::stod(v);  // "nan" parses as NaN
  }
  EXPECT_THAT(keys,
              ElementsAre("frames", "distance_m", "ate_rmse_m", "final_err_m", "final_err_pct",
                          "rpe_trans_pct", "rpe_rot_deg_per_m", "vo_ms_p50", "vo_ms_p99"))
      << report;
  EXPECT_EQ(value["frames"], 95.0);
  EXPECT_EQ(run.frames, 95u);
  EXPECT_GT(run.measurements.size(), 0u) << report;
  ASSERT_TRUE(run.filter_init_stamp.has_value()) << report;
  EXPECT_GT(run.filter_health.Accepted(estimator::InputKind::kRelativePose), 0u) << report;
  EXPECT_EQ(run.outputs_outside_frame_0, 0u);

  // A 4.7 s hover with millimetre motion: sane bounds, not accuracy figures.
  EXPECT_LT(value["ate_rmse_m"], 0.1) << report;
  EXPECT_LT(value["final_err_m"], 0.2) << report;
  EXPECT_GE(value["distance_m"], 0.0);
  EXPECT_LT(value["distance_m"], 1.0);
  EXPECT_GT(value["vo_ms_p50"], 0.0);
  EXPECT_GE(value["vo_ms_p99"], value["vo_ms_p50"]);
  ASSERT_TRUE(run.delta_nees.has_value());
  EXPECT_GT(run.delta_nees->nees.samples.size(), 0u);
  EXPECT_THAT(report, HasSubstr("VO health"));
  EXPECT_THAT(report, HasSubstr("NEES of the VO's relative poses"));

  const ev::Trajectory fused = ev::ReadEurocCsvTrajectory(options.trajectory_out_path);
  EXPECT_EQ(fused.size(), run.filter_outputs);
}

// Bad frames in the stream (black exposures, a frame whose right image is
// missing so the reader drops the pair): the VO refuses and counts them, the
// filter rides on the IMU across the gap, and VO updates resume afterwards.
TEST(VioCommandTest, FilterRidesOnImuAcrossBadFrames) {
  namespace fs = std::filesystem;
  testing::TempDir dir;
  const fs::path copy = dir.path() / "euroc";
  fs::create_directories(copy);
  fs::copy(SharedEuroc() + "/mav0", copy / "mav0", fs::copy_options::recursive);
  std::vector<fs::path> left, right;
  for (const auto& e : fs::directory_iterator(copy / "mav0/cam0/data")) left.push_back(e.path());
  for (const auto& e : fs::directory_iterator(copy / "mav0/cam1/data")) right.push_back(e.path());
  std::sort(left.begin(), left.end());
  std::sort(right.begin(), right.end());
  ASSERT_EQ(left.size(), 95u);
  const cv::Mat black(480, 752, CV_8UC1, cv::Scalar(0));
  for (size_t i = 40; i < 56; ++i) ASSERT_TRUE(cv::imwrite(left[i].string(), black));
  fs::remove(right[70]);

  VioCommandOptions options = EurocOptions();
  options.dataset_dir = copy.string();
  std::ostringstream err;
  const VioRun run = RunVioExperiment(options, err);
  EXPECT_EQ(run.frames, 94u);  // the pair without a right image is left out
  EXPECT_EQ(run.vo_health.Count(estimator::vo::VoStatus::kBlackImage), 16u);
  EXPECT_EQ(run.vo_health.dropped_frames, 1u);
  EXPECT_EQ(run.vo_health.restarts, 0u);
  ASSERT_TRUE(run.filter_init_stamp.has_value());
  // VO updates after the black section, and filter output at every capture since init.
  const Time after_black = Time::FromNanoseconds(std::stoll(left[56].stem().string()));
  int fused_after = 0;
  for (const auto& m : run.measurements) fused_after += m.to_stamp >= after_black ? 1 : 0;
  EXPECT_GT(fused_after, 20);
  EXPECT_GT(run.filter_health.Accepted(estimator::InputKind::kRelativePose), 40u);
  ASSERT_TRUE(run.fused_evaluation.has_value()) << run.fused_error;
  EXPECT_LT(run.fused_evaluation->ate.position_m.rmse, 0.1);
}

TEST(VioCommandTest, MaxFramesAndNoGroundTruth) {
  VioCommandOptions options = EurocOptions();
  options.truth_path.clear();  // the excerpt has no ground-truth CSV of its own
  options.max_frames = 12;
  std::ostringstream out, err;
  const int status = RunVio(options, out, err);
  EXPECT_EQ(status, kExitOk) << err.str();
  const auto fields = ResultOf(out.str());
  ASSERT_EQ(fields.size(), 9u) << out.str();
  EXPECT_EQ(fields[0].second, "12");
  EXPECT_EQ(fields[2].second, "nan");  // ate_rmse_m
  EXPECT_NE(fields[7].second, "nan");  // vo_ms_p50
}

TEST(VioCommandTest, MissingDatasetIsBadInput) {
  VioCommandOptions options;
  options.dataset_dir = "/nonexistent/dataset";
  std::ostringstream out, err;
  EXPECT_EQ(RunVio(options, out, err), kExitBadInput);
  EXPECT_THAT(err.str(), HasSubstr("rover-eval vio: "));
  EXPECT_THAT(err.str(), HasSubstr("/nonexistent/dataset"));
  EXPECT_EQ(out.str(), "");
}

TEST(VioCommandTest, BadFilterConfigIsBadInputNamingTheFile) {
  testing::TempDir dir;
  VioCommandOptions options = EurocOptions();
  options.filter_config_path = WriteFile(dir, "broken.yaml", "init: [1, 2\n");
  std::ostringstream out, err;
  EXPECT_EQ(RunVio(options, out, err), kExitBadInput);
  EXPECT_THAT(err.str(), HasSubstr("broken.yaml"));
}

}  // namespace
}  // namespace rover::host::eval
