// The rover graph on a simulated two-robot sequence (seeded noise): w/v/c/d/o
// factors, late out-of-order insertion, origin marginals, the global pose
// s_j (+) v_t, the sequential-odometry baseline and the error cases.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "core/geometry/so3.h"
#include "core/geometry/yaw.h"
#include "mapping/graph/rover_graph.h"
#include "mapping/graph/sequential_odometry_graph.h"

namespace rover::mapping {
namespace {

constexpr double kPi = std::numbers::pi;
using Vector6 = Eigen::Matrix<double, 6, 1>;

Eigen::Isometry3d MakePose(const Eigen::Vector3d& p, const Eigen::Matrix3d& R) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = p;
  return T;
}

// x, y, z and yaw of T: the gravity-aligned frame at T.
Eigen::Isometry3d FourDof(const Eigen::Isometry3d& T) {
  return MakePose(T.translation(), Rz(YawOf(T.linear())));
}

// The estimate whose truth is T = (p_est + dp, R_est Exp(dtheta)).
Eigen::Isometry3d EstimateFromTruth(const Eigen::Isometry3d& T, const Vector6& delta) {
  return MakePose(T.translation() - delta.head<3>(), T.linear() * ExpSO3(-delta.tail<3>()));
}

Matrix6d Diagonal(double p2, double rp2, double yaw2) {
  Vector6 d;
  d << p2, p2, p2, rp2, rp2, yaw2;
  return d.asDiagonal();
}

// One robot driving `laps` laps of a circle over gentle terrain, with a local
// reference filter whose position and yaw errors random-walk within a submap
// (and reset at each frame switch) while roll and pitch errors stay bounded.
struct RobotSequence {
  static constexpr int kStepsPerSubmap = 10;
  std::vector<Eigen::Isometry3d> truth;    // X_k, world.
  std::vector<Eigen::Isometry3d> origins;  // s_i true (gravity-aligned).
  std::vector<Eigen::Isometry3d> v;        // T_local_body estimates.
  std::vector<Matrix6d> v_cov;
  std::vector<Eigen::Isometry3d> w;  // T_old_new estimates, i -> i+1.
  std::vector<Eigen::Matrix4d> w_cov;
  std::vector<Eigen::Isometry3d> odom;  // Single-frame filter output (baseline).
  std::vector<Matrix6d> odom_cov;
  static constexpr double kSigmaP = 0.03, kSigmaYaw = 0.003, kSigmaRp = 0.01;

  int Submap(int k) const { return k / kStepsPerSubmap; }

  RobotSequence(std::mt19937& rng, const Eigen::Vector3d& center, double radius, int steps,
                double phase) {
    std::normal_distribution<double> n(0.0, 1.0);
    for (int k = 0; k < steps; ++k) {
      const double a = phase + 2.0 * kPi * k / 60.0;
      const Eigen::Vector3d p = center + Eigen::Vector3d(radius * std::cos(a), radius * std::sin(a),
                                                         0.3 * std::sin(3.0 * a));
      const Eigen::Matrix3d R =
          Rz(a + kPi / 2) *
          ExpSO3(Eigen::Vector3d(0.05 * std::sin(5 * a), 0.04 * std::cos(3 * a), 0));
      truth.push_back(MakePose(p, R));
    }
    Vector6 walk = Vector6::Zero();
    for (int k = 0; k < steps; ++k) {
      const int i = Submap(k);
      if (k % kStepsPerSubmap == 0) {
        origins.push_back(FourDof(truth[static_cast<size_t>(k)]));
        walk.setZero();
      }
      const int n_steps = k % kStepsPerSubmap + 1;
      for (int j = 0; j < 3; ++j) walk(j) += kSigmaP * n(rng);
      walk(5) += kSigmaYaw * n(rng);
      Vector6 delta = walk;
      delta(3) = kSigmaRp * n(rng);
      delta(4) = kSigmaRp * n(rng);
      const Eigen::Isometry3d v_true =
          origins[static_cast<size_t>(i)].inverse() * truth[static_cast<size_t>(k)];
      v.push_back(EstimateFromTruth(v_true, delta));
      v_cov.push_back(Diagonal(n_steps * kSigmaP * kSigmaP, kSigmaRp * kSigmaRp,
                               n_steps * kSigmaYaw * kSigmaYaw));
      if ((k + 1) % kStepsPerSubmap == 0 && k + 1 < steps) {
        // Next step switches: w is the 4-DoF part of the filter's estimate of
        // the next pose (one more step of drift).
        Vector6 d2 = walk;
        for (int j = 0; j < 3; ++j) d2(j) += kSigmaP * n(rng);
        d2(5) += kSigmaYaw * n(rng);
        d2(3) = d2(4) = 0.0;
        const Eigen::Isometry3d s_next = FourDof(truth[static_cast<size_t>(k + 1)]);
        const Eigen::Isometry3d w_true = origins[static_cast<size_t>(i)].inverse() * s_next;
        w.push_back(EstimateFromTruth(w_true, d2));
        Eigen::Matrix4d C = Eigen::Matrix4d::Zero();
        C.topLeftCorner<3, 3>() = (n_steps + 1) * kSigmaP * kSigmaP * Eigen::Matrix3d::Identity();
        C(3, 3) = (n_steps + 1) * kSigmaYaw * kSigmaYaw;
        w_cov.push_back(C);
      }
    }
    // Single odometry frame for the baseline: chain the w estimates.
    Eigen::Isometry3d S = origins[0];
    for (int k = 0; k < steps; ++k) {
      const int i = Submap(k);
      if (k > 0 && k % kStepsPerSubmap == 0) S = S * w[static_cast<size_t>(i - 1)];
      odom.push_back(S * v[static_cast<size_t>(k)]);
      odom_cov.push_back(Diagonal((k + 1) * kSigmaP * kSigmaP, kSigmaRp * kSigmaRp,
                                  (k + 1) * kSigmaYaw * kSigmaYaw));
    }
  }
};

Eigen::Isometry3d Noisy(std::mt19937& rng, const Eigen::Isometry3d& T, double sp, double sr) {
  std::normal_distribution<double> n(0.0, 1.0);
  Vector6 d;
  d << sp * n(rng), sp * n(rng), sp * n(rng), sr * n(rng), sr * n(rng), sr * n(rng);
  return EstimateFromTruth(T, d);
}

// The factors of the two-robot scenario as closures, so that tests can feed
// them in any order.
struct Scenario {
  std::mt19937 rng{7};
  RobotSequence r0{rng, {0, 0, 0}, 10.0, 120, 0.0};
  RobotSequence r1{rng, {4, 0, 0.5}, 8.0, 120, 1.0};
  std::vector<std::function<void(RoverGraph&)>> factors;
  Eigen::Isometry3d landmark = MakePose({2, 1, 0.4}, ExpSO3(Eigen::Vector3d(0.1, -0.2, 0.3)));
  static constexpr double kMatchP = 0.05, kMatchR = 0.005;

  void AddRobot(int r, const RobotSequence& s) {
    for (size_t i = 0; i < s.w.size(); ++i) {
      factors.push_back([=, &s](RoverGraph& g) {
        g.AddFrameSwitch(r, static_cast<int64_t>(i), s.w[i], s.w_cov[i]);
      });
    }
    for (size_t k = 0; k < s.v.size(); k += 2) {  // Sparse robot poses.
      factors.push_back([=, &s](RoverGraph& g) {
        g.AddFilterPose(r, s.Submap(static_cast<int>(k)), static_cast<int64_t>(k), s.v[k],
                        s.v_cov[k]);
      });
    }
  }

  // Intra-robot submap matches between laps (60 steps = 6 submaps per lap).
  void AddLoopClosures(int r, const RobotSequence& s) {
    for (size_t i = 0; i + 6 < s.origins.size(); i += 2) {
      const Eigen::Isometry3d T =
          Noisy(rng, s.origins[i].inverse() * s.origins[i + 6], kMatchP, kMatchR);
      factors.push_back([=](RoverGraph& g) {
        g.AddSubmapMatch(r, static_cast<int64_t>(i), r, static_cast<int64_t>(i + 6), T,
                         Diagonal(kMatchP * kMatchP, kMatchR * kMatchR, kMatchR * kMatchR));
      });
    }
  }

  Scenario() {
    AddRobot(0, r0);
    AddRobot(1, r1);
    AddLoopClosures(0, r0);
    AddLoopClosures(1, r1);
    // Inter-robot submap match.
    {
      const Eigen::Isometry3d T =
          Noisy(rng, r0.origins[3].inverse() * r1.origins[2], kMatchP, kMatchR);
      factors.push_back([=](RoverGraph& g) {
        g.AddSubmapMatch(0, 3, 1, 2, T,
                         Diagonal(kMatchP * kMatchP, kMatchR * kMatchR, kMatchR * kMatchR));
      });
    }
    // Robot detections at even steps (poses exist for both robots).
    const Eigen::Isometry3d T_body_cam =
        MakePose({0.3, 0, 0.5}, ExpSO3(Eigen::Vector3d(-kPi / 2, 0, -kPi / 2)));
    const Eigen::Isometry3d T_body_marker =
        MakePose({-0.2, 0, 0.6}, ExpSO3(Eigen::Vector3d(0, kPi / 2, 0)));
    for (const int k : {20, 50, 84, 110}) {
      const auto ku = static_cast<size_t>(k);
      RobotDetection d;
      d.T_body_cam = T_body_cam;
      d.T_body_marker = T_body_marker;
      const Eigen::Isometry3d T_cam_marker_true =
          T_body_cam.inverse() * r0.truth[ku].inverse() * r1.truth[ku] * T_body_marker;
      d.T_cam_marker = Noisy(rng, T_cam_marker_true, 0.05, 0.01);
      d.covariance_cam_marker = Diagonal(0.05 * 0.05, 0.01 * 0.01, 0.01 * 0.01);
      factors.push_back([=](RoverGraph& g) { g.AddRobotDetection(0, k, 1, k, d); });
    }
    // Landmark observations by both robots.
    for (const auto& [r, k] :
         std::vector<std::pair<int, int>>{{0, 10}, {0, 70}, {1, 30}, {1, 90}}) {
      const RobotSequence& s = r == 0 ? r0 : r1;
      const Eigen::Isometry3d T =
          Noisy(rng, s.truth[static_cast<size_t>(k)].inverse() * landmark, 0.05, 0.01);
      factors.push_back([=](RoverGraph& g) {
        g.AddLandmarkObservation(r, k, 0, T, Diagonal(0.05 * 0.05, 1e-4, 1e-4));
      });
    }
  }

  void AddPriors(RoverGraph& g) const {
    g.AddOriginPrior(0, r0.origins[0], Diagonal(1e-8, 1e-8, 1e-8));
    // Robot 1 only loosely knows where it starts: the inter-robot factors place it.
    g.AddOriginPrior(1, r1.origins[0] * MakePose({1.0, -0.5, 0.2}, Rz(0.1)),
                     Diagonal(100.0, 1e-4, 1.0));
  }
};

double PoseRmse(const RoverGraph& g, int robot, const RobotSequence& s) {
  double sum = 0.0;
  int count = 0;
  for (size_t k = 0; k < s.truth.size(); k += 2) {
    sum += (g.Estimate(GraphKey::Pose(robot, static_cast<int64_t>(k))).translation() -
            s.truth[k].translation())
               .squaredNorm();
    ++count;
  }
  return std::sqrt(sum / count);
}

TEST(RoverGraphTest, TwoRobotSequenceWithAllFactorTypes) {
  Scenario sc;
  RoverGraph g;
  sc.AddPriors(g);
  for (const auto& f : sc.factors) f(g);
  const RoverGraphSummary s = g.Optimize();
  EXPECT_TRUE(s.converged);
  // Dead reckoning: the filter estimates chained through the frame switches
  // from the true start (no loop closures, no inter-robot factors).
  auto dead_reckoning_rmse = [](const RobotSequence& r) {
    double sum = 0.0;
    int count = 0;
    for (size_t k = 0; k < r.truth.size(); k += 2) {
      sum += (r.odom[k].translation() - r.truth[k].translation()).squaredNorm();
      ++count;
    }
    return std::sqrt(sum / count);
  };
  const double rmse0 = PoseRmse(g, 0, sc.r0);
  const double rmse1 = PoseRmse(g, 1, sc.r1);
  std::printf("ATE RMSE robot 0: %.3f m (dead reckoning %.3f m), robot 1: %.3f m (%.3f m)\n", rmse0,
              dead_reckoning_rmse(sc.r0), rmse1, dead_reckoning_rmse(sc.r1));
  EXPECT_LT(rmse0, 0.35);
  EXPECT_LT(rmse1, 0.45);
  EXPECT_LT(rmse0, dead_reckoning_rmse(sc.r0));
  EXPECT_LT(rmse1, dead_reckoning_rmse(sc.r1));
  // Robot 1's start (prior off by 1.1 m) is placed by the inter-robot factors.
  const double start1 = (g.Origin(1, 0).translation() - sc.r1.origins[0].translation()).norm();
  const double landmark =
      (g.Estimate(GraphKey::Landmark(0)).translation() - sc.landmark.translation()).norm();
  std::printf("robot 1 origin error %.3f m, landmark error %.3f m\n", start1, landmark);
  EXPECT_LT(start1, 0.5);
  EXPECT_LT(landmark, 0.4);
  // Origins stay gravity-aligned (the w factors' stiff roll/pitch prior).
  for (int i = 0; i < 12; ++i) {
    EXPECT_GT(g.Origin(0, i).linear()(2, 2), std::cos(0.01)) << i;
  }
}

TEST(RoverGraphTest, LateOutOfOrderInsertionGivesTheSameSolution) {
  Scenario sc;
  // Exact (Ceres) solves on both sides: the question here is the insertion
  // order; the incremental solver's gap is tested in incremental_graph_test.
  RoverGraphOptions exact;
  exact.incremental_solve = false;
  RoverGraph in_order(exact);
  sc.AddPriors(in_order);
  const size_t n = sc.factors.size();
  for (size_t k = 0; k < n; ++k) {
    sc.factors[k](in_order);
    if (k % 40 == 39) in_order.Optimize();  // Incremental, warm-started.
  }
  in_order.Optimize();

  std::vector<size_t> order(n);
  for (size_t k = 0; k < n; ++k) order[k] = k;
  std::mt19937 rng(123);
  std::shuffle(order.begin(), order.end(), rng);
  RoverGraph shuffled;
  sc.AddPriors(shuffled);
  for (size_t k = 0; k < n; ++k) sc.factors[order[k]](shuffled);
  shuffled.Optimize();

  for (const GraphKey& key : in_order.Keys()) {
    const Eigen::Isometry3d a = in_order.Estimate(key);
    const Eigen::Isometry3d b = shuffled.Estimate(key);
    EXPECT_LT((a.translation() - b.translation()).norm(), 1e-6) << key.ToString();
    EXPECT_LT(LogSO3(a.linear().transpose() * b.linear()).norm(), 1e-7) << key.ToString();
  }
}

TEST(RoverGraphTest, OriginMarginalsExistAndShrinkAfterLoopClosure) {
  std::mt19937 rng(11);
  RobotSequence s(rng, {0, 0, 0}, 10.0, 120, 0.0);
  RoverGraph g;
  g.AddOriginPrior(0, s.origins[0], Diagonal(1e-8, 1e-8, 1e-8));
  for (size_t i = 0; i < s.w.size(); ++i)
    g.AddFrameSwitch(0, static_cast<int64_t>(i), s.w[i], s.w_cov[i]);
  g.Optimize();
  const size_t last = s.origins.size() - 1;
  Matrix6d before[12];
  for (size_t i = 0; i <= last; ++i) {
    before[i] = g.OriginCovariance(0, static_cast<int64_t>(i));
    EXPECT_GT(before[i].diagonal().minCoeff(), 0.0);
  }
  // Uncertainty grows along the chain.
  EXPECT_GT(before[last].trace(), before[1].trace());
  // Loop closure between the last origin and the first (same place, one lap later: s_6 ~ s_0).
  g.AddSubmapMatch(0, 6, 0, 0, Noisy(rng, s.origins[6].inverse() * s.origins[0], 0.05, 0.005),
                   Diagonal(0.0025, 2.5e-5, 2.5e-5));
  g.Optimize();
  const Matrix6d after = g.OriginCovariance(0, 6);
  EXPECT_LT(after.trace(), 0.5 * before[6].trace());
  EXPECT_LT(g.OriginCovariance(0, 7).trace(), before[7].trace());
}

// Adding origins one frame switch at a time (with a loop closure now and
// then) gives the same estimates and origin marginals as solving everything
// at every step, while the updates that only extend the chain solve nothing.
TEST(RoverGraphTest, IncrementalUpdatesMatchFullSolves) {
  std::mt19937 rng(5);
  RobotSequence s(rng, {0, 0, 0}, 10.0, 120, 0.0);
  RoverGraphOptions full_options;
  full_options.incremental = false;
  // Only the extension path is under test here (loops solve with Ceres); the
  // incremental solver is tested in incremental_graph_test.
  RoverGraphOptions extension_only;
  extension_only.incremental_solve = false;
  RoverGraph incremental(extension_only);
  RoverGraph full(full_options);
  for (RoverGraph* g : {&incremental, &full}) {
    g->AddOriginPrior(0, s.origins[0], Diagonal(1e-8, 1e-8, 1e-8));
  }
  int solves = 0;
  for (size_t i = 0; i < s.w.size(); ++i) {
    const auto submap = static_cast<int64_t>(i);
    const bool loop = i == 6 || i == 9;
    const Eigen::Isometry3d match =
        Noisy(rng, s.origins[i + 1].inverse() * s.origins[i - 6 * loop], 0.05, 0.005);
    for (RoverGraph* g : {&incremental, &full}) {
      g->AddFrameSwitch(0, submap, s.w[i], s.w_cov[i]);
      g->AddFilterPose(0, submap + 1, static_cast<int64_t>(i), s.v[i], s.v_cov[i]);
      if (loop) {
        g->AddSubmapMatch(0, submap + 1, 0, submap + 1 - 7, match,
                          Diagonal(0.0025, 2.5e-5, 2.5e-5));
      }
    }
    const RoverGraphSummary summary = incremental.Optimize();
    full.Optimize();
    solves += summary.solved ? 1 : 0;
    EXPECT_EQ(summary.solved, i == 0 || loop) << "update " << i;
    for (int64_t k = 0; k <= submap + 1; ++k) {
      const Eigen::Isometry3d a = incremental.Origin(0, k);
      const Eigen::Isometry3d b = full.Origin(0, k);
      EXPECT_LT((a.matrix() - b.matrix()).cwiseAbs().maxCoeff(), 1e-6) << "s0_" << k;
      const Matrix6d ca = incremental.OriginCovariance(0, k);
      const Matrix6d cb = full.OriginCovariance(0, k);
      EXPECT_LT((ca - cb).cwiseAbs().maxCoeff(), 1e-6 * cb.cwiseAbs().maxCoeff() + 1e-12)
          << "s0_" << k << " after update " << i;
    }
  }
  EXPECT_EQ(solves, 3);
}

TEST(RoverGraphTest, GlobalPoseIsOriginComposedWithFilterPose) {
  Scenario sc;
  RoverGraph g;
  sc.AddPriors(g);
  for (const auto& f : sc.factors) f(g);
  g.Optimize();
  const Eigen::Isometry3d v_t = MakePose({1.0, 2.0, 0.1}, ExpSO3(Eigen::Vector3d(0.01, 0.02, 0.5)));
  g.SetCurrentFilterPose(0, 5, v_t);
  const Eigen::Isometry3d expected = g.Origin(0, 5) * v_t;
  EXPECT_LT((g.GlobalPose(0).matrix() - expected.matrix()).cwiseAbs().maxCoeff(), 1e-12);
  // Without an explicit current pose: the latest v factor (x^1_118 in submap 11).
  const Eigen::Isometry3d latest = g.Origin(1, 11) * sc.r1.v[118];
  EXPECT_LT((g.GlobalPose(1).matrix() - latest.matrix()).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(RoverGraphTest, LocalReferenceTopologyNoWorseThanSequentialOdometry) {
  std::mt19937 rng(5);
  RobotSequence s(rng, {0, 0, 0}, 10.0, 180, 0.0);
  RoverGraph local;
  SequentialOdometryGraph sequential;
  local.AddOriginPrior(0, s.origins[0], Diagonal(1e-8, 1e-8, 1e-8));
  sequential.AddPrior(0, s.truth[0], Diagonal(1e-8, 1e-8, 1e-8));
  for (size_t i = 0; i < s.w.size(); ++i)
    local.AddFrameSwitch(0, static_cast<int64_t>(i), s.w[i], s.w_cov[i]);
  for (size_t k = 0; k < s.v.size(); ++k) {
    local.AddFilterPose(0, s.Submap(static_cast<int>(k)), static_cast<int64_t>(k), s.v[k],
                        s.v_cov[k]);
    sequential.AddOdometryPose(static_cast<int64_t>(k), s.odom[k], s.odom_cov[k]);
  }
  const Matrix6d C = Diagonal(0.0025, 2.5e-5, 2.5e-5);
  for (size_t i = 0; i + 6 < s.origins.size(); ++i) {
    const size_t j = i + 6;
    local.AddSubmapMatch(0, static_cast<int64_t>(i), 0, static_cast<int64_t>(j),
                         Noisy(rng, s.origins[i].inverse() * s.origins[j], 0.05, 0.005), C);
    const size_t ka = i * RobotSequence::kStepsPerSubmap;
    const size_t kb = j * RobotSequence::kStepsPerSubmap;
    sequential.AddLoopClosure(static_cast<int64_t>(ka), static_cast<int64_t>(kb),
                              Noisy(rng, s.truth[ka].inverse() * s.truth[kb], 0.05, 0.005), C);
  }
  local.Optimize();
  sequential.Optimize();
  double local_sum = 0.0, seq_sum = 0.0;
  for (size_t k = 0; k < s.truth.size(); ++k) {
    local_sum += (local.Estimate(GraphKey::Pose(0, static_cast<int64_t>(k))).translation() -
                  s.truth[k].translation())
                     .squaredNorm();
    seq_sum += (sequential.Pose(static_cast<int64_t>(k)).translation() - s.truth[k].translation())
                   .squaredNorm();
  }
  const double local_rmse = std::sqrt(local_sum / static_cast<double>(s.truth.size()));
  const double seq_rmse = std::sqrt(seq_sum / static_cast<double>(s.truth.size()));
  RecordProperty("local_rmse_m", std::to_string(local_rmse));
  RecordProperty("sequential_rmse_m", std::to_string(seq_rmse));
  std::printf("ATE RMSE: local reference %.4f m, sequential odometry %.4f m\n", local_rmse,
              seq_rmse);
  EXPECT_LE(local_rmse, seq_rmse);
}

TEST(RoverGraphTest, DetectionCovariancePropagationMatchesMonteCarloLinearisation) {
  RobotDetection d;
  d.T_body_cam = MakePose({0.3, 0.1, 0.5}, ExpSO3(Eigen::Vector3d(0.3, -0.2, 1.0)));
  d.T_cam_marker = MakePose({0.5, -1.0, 4.0}, ExpSO3(Eigen::Vector3d(-0.4, 0.2, 0.1)));
  d.T_body_marker = MakePose({-0.2, 0.3, 0.6}, ExpSO3(Eigen::Vector3d(0.2, 1.2, -0.3)));
  d.covariance_cam_marker = Matrix6d::Identity();
  const auto [T, C] = ComposeDetection(d);
  // Numeric Jacobian of the composed pose's [dp; dtheta] w.r.t. the marker's.
  Matrix6d J;
  const double h = 1e-6;
  for (int k = 0; k < 6; ++k) {
    Vector6 delta = Vector6::Zero();
    delta(k) = h;
    RobotDetection moved = d;
    moved.T_cam_marker = MakePose(d.T_cam_marker.translation() + delta.head<3>(),
                                  d.T_cam_marker.linear() * ExpSO3(delta.tail<3>()));
    const Eigen::Isometry3d T2 = ComposeDetection(moved).first;
    J.col(k).head<3>() = (T2.translation() - T.translation()) / h;
    J.col(k).tail<3>() = LogSO3(T.linear().transpose() * T2.linear()) / h;
  }
  EXPECT_LT((J * J.transpose() - C).cwiseAbs().maxCoeff(), 1e-4);
}

TEST(RoverGraphTest, NoPriorIsAGaugeError) {
  RoverGraph g;
  g.AddFrameSwitch(0, 0, Eigen::Isometry3d::Identity(), Eigen::Matrix4d::Identity());
  try {
    g.Optimize();
    FAIL();
  } catch (const GraphError& e) {
    EXPECT_NE(std::string(e.what()).find("no prior"), std::string::npos) << e.what();
  }
}

// A robot no prior reaches yet waits outside the solve, named in the
// summary, while the anchored part is optimised; a match that links it brings
// it in.
TEST(RoverGraphTest, UnanchoredComponentWaitsOutsideTheSolve) {
  RoverGraph g;
  g.AddOriginPrior(0, Eigen::Isometry3d::Identity(), Matrix6d::Identity());
  g.AddFrameSwitch(0, 0, Eigen::Isometry3d::Identity(), Eigen::Matrix4d::Identity());
  g.AddFrameSwitch(1, 0, Eigen::Isometry3d::Identity(), Eigen::Matrix4d::Identity());
  RoverGraphSummary summary = g.Optimize();
  ASSERT_EQ(summary.unanchored.size(), 2u);
  EXPECT_EQ(summary.unanchored[0].ToString(), "s1_0");
  EXPECT_EQ(summary.unanchored[1].ToString(), "s1_1");
  EXPECT_NO_THROW(g.Origin(0, 1));
  EXPECT_THROW(g.Origin(1, 0), GraphError);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(1.0, 2.0, 0.0);
  g.AddSubmapMatch(0, 1, 1, 0, T, Diagonal(1e-4, 1e-6, 1e-6));
  summary = g.Optimize();
  EXPECT_TRUE(summary.unanchored.empty());
  EXPECT_LT((g.Origin(1, 1).translation() - Eigen::Vector3d(1.0, 2.0, 0.0)).norm(), 1e-6);
}

// A landmark whose rotation nothing constrains (every sighting's rotation
// left open) makes the marginals rank deficient. The solve stands, the last
// marginals are kept, the summary says why, and later updates go on from the
// solve (a solver left behind it diverged in a mission).
TEST(RoverGraphTest, MarginalsThatCannotBeComputedKeepTheSolveAndTheLastOnes) {
  RoverGraphOptions options;
  options.incremental_solve = false;  // the full solve computes the marginals with Ceres
  RoverGraph g(options);
  g.AddOriginPrior(0, Eigen::Isometry3d::Identity(), Diagonal(1e-8, 1e-8, 1e-8));
  const Eigen::Isometry3d T_local_body = MakePose({2.0, 0.0, 0.0}, Rz(0.1));
  g.AddFilterPose(0, 0, 1, T_local_body, Diagonal(1e-4, 1e-6, 1e-6));
  ASSERT_TRUE(g.Optimize().covariance_error.empty());
  const Matrix6d before = g.OriginCovariance(0, 0);
  Matrix6d open_rotation = Diagonal(1e-4, 1e-4, 1e-4);
  open_rotation.bottomRightCorner<3, 3>() *= 1e30;
  // Twice: a loop, so the update solves instead of only extending the graph.
  g.AddLandmarkObservation(0, 1, 5, MakePose({3.0, 1.0, 0.0}, Rz(0.3)), open_rotation);
  g.AddLandmarkObservation(0, 1, 5, MakePose({3.0, 1.0, 0.0}, Rz(0.3)), open_rotation);
  RoverGraphSummary summary;
  ASSERT_NO_THROW(summary = g.Optimize());
  EXPECT_TRUE(summary.solved);
  EXPECT_NE(summary.covariance_error.find("rank deficient"), std::string::npos)
      << summary.covariance_error;
  EXPECT_TRUE(g.OriginCovariance(0, 0).isApprox(before));
  g.AddFrameSwitch(0, 0, MakePose({1.0, 0.0, 0.0}, Rz(0.0)), Matrix4d::Identity() * 1e-6);
  g.AddFilterPose(0, 1, 2, T_local_body, Diagonal(1e-4, 1e-6, 1e-6));
  g.Optimize();
  EXPECT_LT((g.Origin(0, 1).translation() - Eigen::Vector3d(1.0, 0.0, 0.0)).norm(), 1e-6);
  EXPECT_LT((g.Estimate(GraphKey::Landmark(5)).translation() -
             (T_local_body * MakePose({3.0, 1.0, 0.0}, Rz(0.3))).translation())
                .norm(),
            1e-6);
}

// A landmark held only by a weak sighting, then seen by a strong one at the
// Cauchy scale (2 sigma): there the strong sighting's exact robust curvature
// along its residual is zero, and the one undamped Gauss-Newton step of an
// online update throws the landmark about a million metres away. The graph
// must not take a step that raises the cost: Ceres settles the update.
TEST(RoverGraphTest, AnIncrementalStepThatRaisesTheCostIsNotTaken) {
  RoverGraph g(RoverGraphOptions::Online());
  const double c = RoverGraphOptions::Online().cauchy_scale;
  g.AddOriginPrior(0, Eigen::Isometry3d::Identity(), Diagonal(1e-8, 1e-8, 1e-8));
  const Eigen::Isometry3d T_local_body = MakePose({2.0, 0.0, 0.0}, Rz(0.0));
  g.AddFilterPose(0, 0, 1, T_local_body, Diagonal(1e-8, 1e-8, 1e-8));
  g.AddFilterPose(0, 0, 2, T_local_body, Diagonal(1e-8, 1e-8, 1e-8));
  const Eigen::Isometry3d T_body_landmark = MakePose({3.0, 0.0, 0.0}, Rz(0.0));
  const double weak_sigma_m = 100.0, strong_sigma_m = 0.01;
  g.AddLandmarkObservation(0, 1, 5, T_body_landmark,
                           Diagonal(weak_sigma_m * weak_sigma_m, 1e-4, 1e-4));
  ASSERT_TRUE(g.Optimize().solved);
  Eigen::Isometry3d strong = T_body_landmark;
  strong.translation().x() += c * strong_sigma_m;
  g.AddLandmarkObservation(0, 2, 5, strong, Diagonal(strong_sigma_m * strong_sigma_m, 1e-4, 1e-4));
  const RoverGraphSummary summary = g.Optimize();
  EXPECT_TRUE(summary.solved);
  EXPECT_FALSE(summary.incremental_solve);
  EXPECT_LT(summary.final_cost, summary.initial_cost + 2.0);
  const Eigen::Vector3d p_landmark = g.Estimate(GraphKey::Landmark(5)).translation();
  EXPECT_LT((p_landmark - (T_local_body * strong).translation()).norm(), 0.05) << p_landmark;
  while (g.NeedsRefinement()) g.Refine();
  EXPECT_LT((g.Estimate(GraphKey::Landmark(5)).translation() - p_landmark).norm(), 0.05);
}

TEST(RoverGraphTest, NanInputIsRejected) {
  RoverGraph g;
  Eigen::Isometry3d bad = Eigen::Isometry3d::Identity();
  bad.translation().x() = std::numeric_limits<double>::quiet_NaN();
  try {
    g.AddFilterPose(0, 0, 1, bad, Matrix6d::Identity());
    FAIL();
  } catch (const GraphError& e) {
    EXPECT_NE(std::string(e.what()).find("NaN input: measurement of factor s0_0 -> x0_1"),
              std::string::npos)
        << e.what();
  }
  Matrix6d cov = Matrix6d::Identity();
  cov(2, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(g.AddOriginPrior(0, Eigen::Isometry3d::Identity(), cov), GraphError);
  EXPECT_THROW(g.AddOriginPrior(0, Eigen::Isometry3d::Identity(), -Matrix6d::Identity()),
               GraphError);
}

}  // namespace
}  // namespace rover::mapping
