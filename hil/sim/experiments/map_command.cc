#include "hil/sim/experiments/map_command.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "core/config/config.h"
#include "core/geometry/yaw.h"
#include "core/log/mcap/mcap_reader.h"
#include "core/log/msgs/estimator_msgs.h"
#include "core/log/msgs/message_traits.h"
#include "core/stats/percentile.h"
#include "estimator/eskf/eskf_output.h"
#include "hil/sim/dataset/dataset_generator.h"
#include "hil/sim/experiments/loop_replay.h"
#include "hil/sim/motion/rover_trajectory.h"
#include "hil/sim/scenario/scenario.h"
#include "hil/sim/scenario/team_rovers.h"
#include "mapping/compose/map_composer.h"
#include "mapping/compose/map_export.h"
#include "mapping/compose/submap_log.h"
#include "mapping/graph/rover_graph.h"
#include "mapping/slam/false_match_injection.h"
#include "mapping/slam/graph_log.h"
#include "mapping/slam/team_graph.h"
#include "mapping/tags/tag_log.h"

namespace rover::sim::experiments {

using cli::kExitBadInput;
using cli::kExitOk;
using cli::Subcommand;
namespace {

// What the mission log tells about the run.
struct MissionFacts {
  std::string scenario;
  /// Which rover of the scenario the mission simulated (team_rovers.h); 0
  /// for logs from before team scenarios, which have no "rover".
  std::size_t rover = 0;
  uint64_t seed = 1;
  Time start;
  bool has_start = false;
  /// The first initialised estimate (frame 0): stamp and pose.
  Time init_stamp;
  Eigen::Isometry3d T_local0_body_init = Eigen::Isometry3d::Identity();
  bool initialised = false;
  Time last_stamp;
};

MissionFacts ReadMission(const std::string& path) {
  log::McapReader reader = [&path] {
    try {
      return log::McapReader::Open(path);
    } catch (const std::exception& e) {
      throw std::runtime_error(path + ": not a readable MCAP log: " + e.what());
    }
  }();
  MissionFacts f;
  bool lockstep = true;
  for (const log::Metadata& m : reader.metadata()) {
    if (m.name != "mission") continue;
    if (m.metadata.count("scenario")) f.scenario = m.metadata.at("scenario");
    if (m.metadata.count("seed")) f.seed = std::stoull(m.metadata.at("seed"));
    if (m.metadata.count("rover")) {
      const std::string& text = m.metadata.at("rover");
      std::size_t used = 0;
      try {
        f.rover = std::stoull(text, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used == 0 || used != text.size()) {
        throw std::runtime_error(path + ": mission metadata rover=\"" + text +
                                 "\" is not a rover index");
      }
    }
    if (m.metadata.count("lockstep")) lockstep = m.metadata.at("lockstep") == "true";
    if (m.metadata.count("start_ns")) {
      f.start = Time::FromNanoseconds(std::stoll(m.metadata.at("start_ns")));
      f.has_start = true;
    }
  }
  // Lockstep missions run on the datasets' fixed time origin.
  if (!f.has_start && lockstep) {
    f.start = sim::kDatasetStartTime;
    f.has_start = true;
  }
  uint16_t state_channel = 0;
  for (const auto& [id, channel] : reader.channels()) {
    if (channel.topic == "/estimator/state") state_channel = id;
  }
  reader.ForEachMessage([&](const log::MessageView& m) {
    if (m.channel_id != state_channel) return true;
    log::rover_msgs::EstimatorState s;
    if (!log::DeserializeMessage(m.data, &s)) return true;
    f.last_stamp = Time::FromNanoseconds(s.stamp_ns);
    if (f.initialised || (s.status & estimator::kStatusNotInitialised) != 0) return true;
    f.initialised = true;
    f.init_stamp = Time::FromNanoseconds(s.stamp_ns);
    const auto& q = s.q_local_body_xyzw;
    f.T_local0_body_init.linear() =
        Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized().toRotationMatrix();
    f.T_local0_body_init.translation() =
        Eigen::Vector3d(s.p_local_body_m[0], s.p_local_body_m[1], s.p_local_body_m[2]);
    return true;
  });
  if (!f.initialised) throw std::runtime_error(path + ": the filter never initialised");
  return f;
}

// Position and yaw only: local frames are gravity-aligned.
Eigen::Isometry3d FourDof(const Eigen::Vector3d& p, const Eigen::Matrix3d& R) {
  return GravityAlignedTransform(p, YawOf(R));
}

// Frame 0 of `mission` in the world: the true body pose at initialisation
// against the filter's estimate then (x, y, z, yaw).
Eigen::Isometry3d TrueFrameZero(const MissionFacts& mission,
                                const sim::RoverTrajectory& trajectory) {
  const sim::TrajectorySample truth =
      trajectory.Evaluate((mission.init_stamp - mission.start).ToSeconds());
  return FourDof(truth.p_world_body, truth.q_world_body.toRotationMatrix()) *
         FourDof(mission.T_local0_body_init.translation(), mission.T_local0_body_init.linear())
             .inverse();
}

// The true pose of `T_body_cam` at time `t` of `mission`.
Eigen::Isometry3d TrueCamera(const MissionFacts& mission, const sim::RoverTrajectory& trajectory,
                             const Eigen::Isometry3d& T_body_cam, Time t) {
  const sim::TrajectorySample s = trajectory.Evaluate((t - mission.start).ToSeconds());
  Eigen::Isometry3d T_world_body = Eigen::Isometry3d::Identity();
  T_world_body.linear() = s.q_world_body.toRotationMatrix();
  T_world_body.translation() = s.p_world_body;
  return T_world_body * T_body_cam;
}

// The true camera along the mapped part of `mission`, every 0.25 s.
void AppendTrueCameras(const MissionFacts& mission, const sim::RoverTrajectory& trajectory,
                       const Eigen::Isometry3d& T_body_cam,
                       std::vector<Eigen::Isometry3d>* cameras) {
  for (Time t = mission.init_stamp; t <= mission.last_stamp; t = t + Duration::FromSeconds(0.25)) {
    cameras->push_back(TrueCamera(mission, trajectory, T_body_cam, t));
  }
}

std::string Num(double v, int digits) {
  if (!std::isfinite(v)) return "nan";
  char text[48];
  std::snprintf(text, sizeof(text), "%.*f", digits, v);
  return text;
}

// The true origins of the graph's local frames. A local frame starts at the
// body's position and yaw at its switch, so its true origin is the true body
// pose then (x, y, z, yaw); frame 0's is T_world_local0.
std::map<int64_t, Eigen::Isometry3d> TrueOrigins(const mapping::GraphLogContents& g,
                                                 const sim::RoverTrajectory& trajectory,
                                                 const MissionFacts& mission,
                                                 const Eigen::Isometry3d& T_world_local0) {
  std::map<int64_t, Eigen::Isometry3d> truth;
  for (const mapping::GraphFactorRecord& f : g.factors) {
    if (f.kind == mapping::FactorKind::kPrior && f.a.index == 0) truth[0] = T_world_local0;
    if (f.kind != mapping::FactorKind::kFrameSwitch) continue;
    const double t_s = (Time::FromNanoseconds(f.stamp_ns) - mission.start).ToSeconds();
    const sim::TrajectorySample s = trajectory.Evaluate(t_s);
    truth[f.a.index + 1] = FourDof(s.p_world_body, s.q_world_body.toRotationMatrix());
  }
  return truth;
}

// Yaw of T_a_b less the true one, wrapped to [-pi, pi].
double YawErrorRad(const Eigen::Isometry3d& T_a_b, const Eigen::Isometry3d& T_a_b_true) {
  return std::remainder(YawOf(T_a_b.linear()) - YawOf(T_a_b_true.linear()), 2.0 * M_PI);
}

// Calls visit(factor, T_a_b_true) for each two-origin factor of `kind` whose
// origins both have a known truth.
template <typename Visit>
void ForEachFactorWithTruth(const mapping::GraphLogContents& g,
                            const std::map<int64_t, Eigen::Isometry3d>& truth,
                            mapping::FactorKind kind, Visit visit) {
  for (const mapping::GraphFactorRecord& f : g.factors) {
    if (f.kind != kind || !f.b) continue;
    const auto a = truth.find(f.a.index);
    const auto b = truth.find(f.b->index);
    if (a == truth.end() || b == truth.end()) continue;
    visit(f, Eigen::Isometry3d(a->second.inverse() * b->second));
  }
}

// Counts the graph's submap matches and those that hold against the true
// origins. A match naming a frame of unknown truth counts as invalid.
void ScoreLoopClosures(const mapping::GraphLogContents& g,
                       const std::map<int64_t, Eigen::Isometry3d>& truth, MapResult* r) {
  for (const mapping::GraphFactorRecord& f : g.factors) {
    if (f.kind != mapping::FactorKind::kSubmapMatch || !f.b) continue;
    ++r->loop_closures;
    const auto a = truth.find(f.a.index);
    const auto b = truth.find(f.b->index);
    if (a == truth.end() || b == truth.end()) continue;
    if (IsValidLoopClosure(f.T_a_b, a->second.inverse() * b->second)) ++r->loop_closures_valid;
  }
  r->loop_closure_precision = r->loop_closures > 0 ? static_cast<double>(r->loop_closures_valid) /
                                                         static_cast<double>(r->loop_closures)
                                                   : std::numeric_limits<double>::quiet_NaN();
}

// The accepted submap matches' errors against the truth (median and p90 of
// the translation and yaw), and a diagnostic: the constant offset d in the
// origins' frames that best explains them. Origins (or submap content) all
// shifted by d make a match of relative yaw R read t + (R - I) d, so a
// consistent d with a small residual points at a bias common to every submap
// (a stamp offset, a depth bias along the view) rather than at the matcher.
void ReportLoopClosureErrors(const mapping::GraphLogContents& g,
                             const std::map<int64_t, Eigen::Isometry3d>& truth,
                             std::ostream& report) {
  std::vector<double> translation_m, yaw_deg;
  // Per match: A = R - I (xy block) and the xy error, for the offset fit.
  std::vector<std::pair<Eigen::Matrix2d, Eigen::Vector2d>> rows;
  std::ostringstream invalid;
  ForEachFactorWithTruth(
      g, truth, mapping::FactorKind::kSubmapMatch, [&](const auto& f, const auto& T_true) {
        const Eigen::Vector3d e = f.T_a_b.translation() - T_true.translation();
        const double yaw_error_deg = YawErrorRad(f.T_a_b, T_true) * 180.0 / M_PI;
        if (!IsValidLoopClosure(f.T_a_b, T_true)) {
          const Eigen::Matrix4d P = mapping::FourDofBlock(f.covariance);
          invalid << " | " << f.a.index << "-" << f.b->index << " " << Num(e.norm(), 3) << " m "
                  << Num(yaw_error_deg, 2) << " deg (sigma " << Num(std::sqrt(P(0, 0) + P(1, 1)), 3)
                  << " m " << Num(std::sqrt(P(3, 3)) * 180.0 / M_PI, 2) << " deg)";
        }
        translation_m.push_back(e.norm());
        yaw_deg.push_back(std::abs(yaw_error_deg));
        rows.emplace_back(
            T_true.linear().template topLeftCorner<2, 2>() - Eigen::Matrix2d::Identity(),
            e.head<2>());
      });
  if (translation_m.empty()) return;
  report << "  submap matches vs truth: " << translation_m.size() << "; translation median "
         << Num(stats::Percentile(translation_m, 50.0), 3) << " m, p90 "
         << Num(stats::Percentile(translation_m, 90.0), 3) << " m; yaw median "
         << Num(stats::Percentile(yaw_deg, 50.0), 2) << " deg, p90 "
         << Num(stats::Percentile(yaw_deg, 90.0), 2) << " deg";
  Eigen::Matrix2d AtA = Eigen::Matrix2d::Zero();
  Eigen::Vector2d Atb = Eigen::Vector2d::Zero();
  for (const auto& [A, e] : rows) {
    AtA += A.transpose() * A;
    Atb += A.transpose() * e;
  }
  if (AtA.determinant() > 1e-6) {
    const Eigen::Vector2d d = AtA.ldlt().solve(Atb);
    double before = 0.0, after = 0.0;
    for (const auto& [A, e] : rows) {
      before += e.squaredNorm();
      after += (e - A * d).squaredNorm();
    }
    const double n = static_cast<double>(rows.size());
    report << "; a common origin offset (x " << Num(d(0), 3) << " m, y " << Num(d(1), 3)
           << " m) would explain xy RMS " << Num(std::sqrt(before / n), 3) << " -> "
           << Num(std::sqrt(after / n), 3) << " m";
  }
  report << "\n";
  if (!invalid.str().empty())
    report << "  invalid matches: a-b error (sigma)" << invalid.str() << "\n";
}

// How the frame switches (w factors) hold against the truth: each switch's
// error in its old frame (x: the heading at the frame's start, so mostly
// along-track), normalised by the covariance the graph gives it. Consistent
// covariances give a normalised RMS near 1 per axis and a mean NEES near 4.
void ReportFrameSwitchConsistency(const mapping::GraphLogContents& g,
                                  const std::map<int64_t, Eigen::Isometry3d>& truth, MapResult* r,
                                  std::ostream& report) {
  Eigen::Vector4d sum = Eigen::Vector4d::Zero(), sum_sq = Eigen::Vector4d::Zero();
  Eigen::Vector4d normalised_sq = Eigen::Vector4d::Zero();
  double nees_sum = 0.0, distance_sum_m = 0.0;
  int n = 0;
  ForEachFactorWithTruth(g, truth, mapping::FactorKind::kFrameSwitch,
                         [&](const auto& f, const auto& T_true) {
                           Eigen::Vector4d e;
                           e.head<3>() = f.T_a_b.translation() - T_true.translation();
                           e(3) = YawErrorRad(f.T_a_b, T_true);
                           const Eigen::Matrix4d P = mapping::FourDofBlock(f.covariance);
                           sum += e;
                           sum_sq += e.cwiseAbs2();
                           normalised_sq += e.cwiseAbs2().cwiseQuotient(P.diagonal());
                           nees_sum += e.dot(P.ldlt().solve(e));
                           distance_sum_m += T_true.translation().norm();
                           ++n;
                         });
  if (n == 0) return;
  const Eigen::Vector4d mean = sum / n;
  const Eigen::Vector4d sd = (sum_sq / n - mean.cwiseAbs2()).cwiseMax(0.0).cwiseSqrt();
  const Eigen::Vector4d nrms = (normalised_sq / n).cwiseSqrt();
  r->frame_switch_nees = nees_sum / n;
  report << "  frame switches vs truth: " << n << " of " << Num(distance_sum_m / n, 2)
         << " m; error per switch (old frame) x " << Num(mean(0), 4) << " +- " << Num(sd(0), 4)
         << " m, y " << Num(mean(1), 4) << " +- " << Num(sd(1), 4) << " m, z " << Num(mean(2), 4)
         << " +- " << Num(sd(2), 4) << " m, yaw " << Num(mean(3) * 180.0 / M_PI, 3) << " +- "
         << Num(sd(3) * 180.0 / M_PI, 3) << " deg; normalised RMS x " << Num(nrms(0), 2) << " y "
         << Num(nrms(1), 2) << " z " << Num(nrms(2), 2) << " yaw " << Num(nrms(3), 2)
         << "; mean NEES " << Num(r->frame_switch_nees, 2) << " (consistent: 4)\n";
}

// The logged graph re-solved, with `extra` factors, optionally without the
// tag sightings (v, o) and with the frame switches' sigmas scaled.
// This rover's part of a logged graph: the factors whose keys are all its
// own (or landmarks). A team rover's log also holds what the others sent,
// which the truth of this rover cannot score.
mapping::GraphLogContents OwnPart(const mapping::GraphLogContents& g, int robot) {
  const auto own = [robot](const mapping::GraphKey& k) {
    return k.type == mapping::GraphKey::Type::kLandmark || k.robot == robot;
  };
  mapping::GraphLogContents out = g;
  out.factors.clear();
  out.messages.clear();
  for (std::size_t k = 0; k < g.factors.size(); ++k) {
    const mapping::GraphFactorRecord& f = g.factors[k];
    if (!own(f.a) || (f.b && !own(*f.b))) continue;
    out.factors.push_back(f);
    out.messages.push_back(g.messages[k]);
  }
  return out;
}

std::unique_ptr<mapping::RoverGraph> Resolved(const mapping::GraphLogContents& g,
                                              const std::vector<mapping::GraphFactorRecord>& extra,
                                              double switch_sigma_scale, bool without_tags) {
  auto graph = std::make_unique<mapping::RoverGraph>();
  for (mapping::GraphFactorRecord f : g.factors) {
    if (without_tags && (f.kind == mapping::FactorKind::kFilterPose ||
                         f.kind == mapping::FactorKind::kLandmarkObservation)) {
      continue;
    }
    if (f.kind == mapping::FactorKind::kFrameSwitch) {
      f.covariance *= switch_sigma_scale * switch_sigma_scale;
    }
    mapping::AddToGraph(f, graph.get());
  }
  for (const mapping::GraphFactorRecord& f : extra) mapping::AddToGraph(f, graph.get());
  graph->Optimize();
  return graph;
}

// The final global pose after re-solving the logged graph, with `extra`
// factors: the logged pose's offset from its frame's logged origin (its
// frame: the newest origin) moved with that origin.
Eigen::Vector3d ResolvedFinalPosition(const mapping::GraphLogContents& g,
                                      const std::vector<mapping::GraphFactorRecord>& extra,
                                      double switch_sigma_scale = 1.0, bool without_tags = false) {
  return mapping::MovedFinalGlobalPose(g, *Resolved(g, extra, switch_sigma_scale, without_tags))
      .translation();
}

// Re-solves the logged graph as it is and with false matches added, and
// scores both final positions as the logged one.
void ScoreFalseMatches(const mapping::GraphLogContents& g, const Eigen::Isometry3d& T_world_graph,
                       const Eigen::Vector3d& p_true, double distance_m, const MapCommandOptions& o,
                       MapResult* r, std::ostream& report) {
  if (g.last_origins->origins.empty()) return;
  std::map<int64_t, Eigen::Isometry3d> estimates;
  for (const log::rover_msgs::SubmapOrigin& origin : g.last_origins->origins) {
    estimates[origin.submap] = mapping::FromPoseMsg(origin.pose);
  }
  mapping::FalseMatchOptions options;
  options.fraction = o.false_match_fraction;
  options.seed = o.false_match_seed;
  const std::vector<mapping::GraphFactorRecord> false_matches = mapping::MakeFalseSubmapMatches(
      g.factors, g.last_origins->origins.front().robot, estimates, options);
  r->false_matches = false_matches.size();
  const Eigen::Vector3d as_logged = T_world_graph * ResolvedFinalPosition(g, {});
  const Eigen::Vector3d with_false = T_world_graph * ResolvedFinalPosition(g, false_matches);
  r->resolved_error_pct = 100.0 * (as_logged - p_true).norm() / distance_m;
  r->false_match_error_pct = 100.0 * (with_false - p_true).norm() / distance_m;
  if (o.switch_sigma_scale != 1.0) {
    const Eigen::Vector3d scaled =
        T_world_graph * ResolvedFinalPosition(g, {}, o.switch_sigma_scale);
    report << "  re-solved with the frame switches' sigmas x" << Num(o.switch_sigma_scale, 2)
           << ": final error " << Num(100.0 * (scaled - p_true).norm() / distance_m, 4) << " %\n";
  }
  report << "  false matches: the logged graph re-solved: final error "
         << Num(r->resolved_error_pct, 4) << " %; with " << false_matches.size()
         << " false matches added (" << Num(100.0 * o.false_match_fraction, 0)
         << " % of all matches): " << Num(r->false_match_error_pct, 4) << " %\n";
}

// With tag sightings in the graph: the logged graph re-solved whole and
// without them, scored as the logged final position.
void ScoreTagSightings(const mapping::GraphLogContents& g, const Eigen::Isometry3d& T_world_graph,
                       const Eigen::Vector3d& p_true, double distance_m,
                       const std::function<Eigen::Vector3d(int64_t)>& truth_at, MapResult* r,
                       std::ostream& report) {
  uint64_t factors = 0;
  for (const mapping::GraphFactorRecord& f : g.factors) {
    factors += f.kind == mapping::FactorKind::kLandmarkObservation;
  }
  r->tag_factors = factors;
  if (factors == 0 || distance_m <= 0.0) return;
  const std::unique_ptr<mapping::RoverGraph> with_tags = Resolved(g, {}, 1.0, false);
  const Eigen::Vector3d whole =
      T_world_graph * mapping::MovedFinalGlobalPose(g, *with_tags).translation();
  const std::unique_ptr<mapping::RoverGraph> without_tags = Resolved(g, {}, 1.0, true);
  const Eigen::Vector3d without =
      T_world_graph * mapping::MovedFinalGlobalPose(g, *without_tags).translation();
  // Where the graph puts the sighting poses against the truth, with the
  // sightings and without (their frame's origin and the filter's estimate).
  std::vector<double> with_m, without_m;
  for (const mapping::GraphFactorRecord& f : g.factors) {
    if (f.kind != mapping::FactorKind::kFilterPose) continue;
    const Eigen::Vector3d truth = truth_at(f.stamp_ns);
    with_m.push_back((T_world_graph * with_tags->Estimate(*f.b).translation() - truth).norm());
    without_m.push_back(
        (T_world_graph * (without_tags->Estimate(f.a) * f.T_a_b).translation() - truth).norm());
  }
  if (!with_m.empty()) {
    report << "  the sighting poses vs truth: median " << Num(stats::Percentile(with_m, 50.0), 3)
           << " m with the sightings, " << Num(stats::Percentile(without_m, 50.0), 3)
           << " m without; the last " << Num(with_m.back(), 3) << " m with, "
           << Num(without_m.back(), 3) << " m without\n";
  }
  r->slam_resolved_error_pct = 100.0 * (whole - p_true).norm() / distance_m;
  r->slam_without_tags_error_pct = 100.0 * (without - p_true).norm() / distance_m;
  report << "  tag sightings: " << factors << " o factors; the logged graph re-solved: final "
         << "error " << Num(r->slam_resolved_error_pct, 4) << " %, without the sightings "
         << Num(r->slam_without_tags_error_pct, 4) << " %\n";
}

// In a team: the logged graph re-solved whole (the team's factors in it)
// and with this rover's own factors alone, scored as the logged final
// position: what the team did for this rover on the same run.
void ScoreTeam(const mapping::GraphLogContents& all, const mapping::GraphLogContents& own,
               const Eigen::Isometry3d& T_world_graph, const Eigen::Vector3d& p_true,
               double distance_m, MapResult* r, std::ostream& report) {
  r->team_factors = all.factors.size() - own.factors.size();
  if (r->team_factors == 0 || distance_m <= 0.0) return;
  const Eigen::Vector3d whole =
      T_world_graph *
      mapping::MovedFinalGlobalPose(all, *Resolved(all, {}, 1.0, false)).translation();
  const Eigen::Vector3d alone =
      T_world_graph *
      mapping::MovedFinalGlobalPose(own, *Resolved(own, {}, 1.0, false)).translation();
  r->slam_team_resolved_error_pct = 100.0 * (whole - p_true).norm() / distance_m;
  r->slam_alone_error_pct = 100.0 * (alone - p_true).norm() / distance_m;
  report << "  team: " << r->team_factors << " factors name other rovers; the logged graph "
         << "re-solved: final error " << Num(r->slam_team_resolved_error_pct, 4)
         << " %, this rover's factors alone " << Num(r->slam_alone_error_pct, 4) << " %\n";
}

// Each optimised origin's error against its true origin, both taken relative
// to the graph's first origin: where along the mission the graph's error
// grows (every 5th origin and the last).
void ReportOriginErrors(const mapping::GraphLogContents& g,
                        const std::map<int64_t, Eigen::Isometry3d>& truth, std::ostream& report) {
  if (!g.last_origins || g.last_origins->origins.empty()) return;
  std::map<int64_t, Eigen::Isometry3d> estimate;
  for (const log::rover_msgs::SubmapOrigin& o : g.last_origins->origins) {
    estimate[o.submap] = mapping::FromPoseMsg(o.pose);
  }
  const auto first = estimate.begin();
  const auto first_true = truth.find(first->first);
  if (first_true == truth.end()) return;
  report << "  origins vs truth (relative to origin " << first->first << "): submap m deg";
  const int64_t last = estimate.rbegin()->first;
  for (const auto& [frame, T_graph_origin] : estimate) {
    if (frame % 5 != 0 && frame != last) continue;
    const auto t = truth.find(frame);
    if (t == truth.end()) continue;
    const Eigen::Isometry3d est = first->second.inverse() * T_graph_origin;
    const Eigen::Isometry3d tru = first_true->second.inverse() * t->second;
    const Eigen::Isometry3d err = tru.inverse() * est;
    report << " | " << frame << " " << Num(err.translation().norm(), 3) << " "
           << Num(std::atan2(err.linear()(1, 0), err.linear()(0, 0)) * 180.0 / M_PI, 2);
  }
  report << "\n";
}

// Diagnostic for submaps placed at their true origins (map_evaluation.h).
void ReportContentShift(const sim::Heightfield& terrain,
                        const std::vector<mapping::SubmapLog>& logs,
                        const std::map<uint32_t, Eigen::Isometry3d>& origins,
                        std::ostream& report) {
  std::vector<PlacedCloud> clouds;
  for (const mapping::SubmapLog& log : logs) {
    for (const mapping::LoggedSubmap& s : log.submaps) {
      const auto origin = origins.find(s.info.frame_id);
      if (s.cloud && origin != origins.end()) clouds.push_back({origin->second, s.cloud.get()});
    }
  }
  const ContentShift shift = EstimateContentShift(terrain, clouds);
  if (!shift.ok) {
    report << "  submap content vs the true terrain: too few points on slopes to tell\n";
    return;
  }
  report << "  submap content vs the true terrain (" << shift.points
         << " cloud points): shifted forward " << Num(shift.forward_m, 3) << " m, left "
         << Num(shift.left_m, 3) << " m, up " << Num(shift.up_m, 3)
         << " m in each submap's frame\n";
}

// The submaps at the pose graph's optimised origins (mapping::
// PlaceAtGraphOrigins), and the graph's final global pose against the truth.
// A restarted mapd's log holds the whole graph again; later logs win.
void PlaceAtGraphOrigins(const std::vector<std::string>& mapd_logs,
                         const sim::RoverTrajectory& trajectory, const MissionFacts& mission,
                         const Eigen::Isometry3d& T_world_local0, const MapCommandOptions& options,
                         std::map<uint32_t, Eigen::Isometry3d>* origins, MapResult* r,
                         std::ostream& report) {
  for (const std::string& path : mapd_logs) {
    const mapping::GraphLogContents all = mapping::ReadGraphLogs({path});
    for (const std::string& p : all.problems) report << "    graph: " << p << "\n";
    // The log's own robot: that of its origins (mapd logs only its own).
    const int self = all.last_origins && !all.last_origins->origins.empty()
                         ? all.last_origins->origins.front().robot
                         : static_cast<int>(mission.rover);
    mapping::GraphLogContents g = OwnPart(all, self);
    if (options.rematch) {
      LoopReplayOptions replay;
      replay.reapply_switch_noise = options.rematch_reapply_switch_noise;
      if (!options.rematch_loop_config.empty()) {
        replay.loop =
            mapd::LoopCloserOptions::Load(ConfigNode::LoadFile(options.rematch_loop_config));
      }
      replay.true_origins = TrueOrigins(g, trajectory, mission, T_world_local0);
      replay.explain_pairs = options.explain_pairs;
      const LoopReplayResult result =
          ReplayLoopClosing(g, mapping::ReadSubmapLog(path), replay, report);
      report << "  loop closing replayed offline: " << result.matches_accepted << " accepted of "
             << result.pairs_matched << " pairs matched; " << result.submaps_suitable
             << " submaps suitable\n";
      g = result.graph;
    }
    const std::map<int64_t, Eigen::Isometry3d> truth =
        TrueOrigins(g, trajectory, mission, T_world_local0);
    ScoreLoopClosures(g, truth, r);
    ReportLoopClosureErrors(g, truth, report);
    ReportFrameSwitchConsistency(g, truth, r, report);
    ReportOriginErrors(g, truth, report);
    if (options.true_origins) {
      // Diagnostic: what the submaps alone are worth, with no origin error.
      for (const auto& [frame, T_world_origin] : truth) {
        (*origins)[static_cast<uint32_t>(frame)] = T_world_origin;
      }
      report << "  submaps placed at their true origins (diagnostic)\n";
      continue;
    }
    if (!g.last_origins) continue;
    const std::optional<Eigen::Isometry3d> T_world_graph =
        mapping::GraphInMap(*g.last_origins, *origins);
    if (!T_world_graph) continue;
    r->graph_origins += mapping::PlaceAtGraphOrigins(*g.last_origins, origins);
    if (!g.last_global_pose) continue;
    const Time stamp = log::FromRosTime(g.last_global_pose->header.stamp);
    const Eigen::Vector3d p_est =
        (*T_world_graph * mapping::FromPoseMsg(g.last_global_pose->pose.pose)).translation();
    const double t_s = (stamp - mission.start).ToSeconds();
    const Eigen::Vector3d p_true = trajectory.Evaluate(t_s).p_world_body;
    double distance_m = 0.0;
    Eigen::Vector3d previous =
        trajectory.Evaluate((mission.init_stamp - mission.start).ToSeconds()).p_world_body;
    for (double t = (mission.init_stamp - mission.start).ToSeconds(); t <= t_s; t += 0.1) {
      const Eigen::Vector3d p = trajectory.Evaluate(t).p_world_body;
      distance_m += (p - previous).norm();
      previous = p;
    }
    r->slam_final_error_m = (p_est - p_true).norm();
    r->slam_final_error_pct = distance_m > 0.0 ? 100.0 * r->slam_final_error_m / distance_m
                                               : std::numeric_limits<double>::quiet_NaN();
    ScoreTagSightings(
        g, *T_world_graph, p_true, distance_m,
        [&](int64_t stamp_ns) {
          return trajectory.Evaluate((Time::FromNanoseconds(stamp_ns) - mission.start).ToSeconds())
              .p_world_body;
        },
        r, report);
    ScoreTeam(all, g, *T_world_graph, p_true, distance_m, r, report);
    if ((options.false_match_fraction > 0.0 || options.switch_sigma_scale != 1.0) &&
        distance_m > 0.0) {
      ScoreFalseMatches(g, *T_world_graph, p_true, distance_m, options, r, report);
    }
  }
}

}  // namespace

MapResult EvaluateMission(const MapCommandOptions& o, std::ostream& report) {
  const MissionFacts mission = ReadMission(o.mission_log);
  const std::string scenario_name = o.scenario.empty() ? mission.scenario : o.scenario;
  if (scenario_name.empty()) {
    throw std::runtime_error(o.mission_log + ": no mission metadata; give --scenario and --seed");
  }
  if (!mission.has_start) {
    throw std::runtime_error(o.mission_log +
                             ": a real-time mission without its start time (start_ns)");
  }
  const uint64_t seed = o.seed >= 0 ? static_cast<uint64_t>(o.seed) : mission.seed;
  const sim::Scenario scenario = sim::LoadScenario(
      sim::FindScenario(sim::DefaultScenarioDir(), scenario_name), sim::DefaultSimConfigDir());
  const sim::World world = sim::World::Generate(scenario.world, seed);
  // The ground truth is the trajectory of the rover the mission simulated.
  const std::size_t rover = o.rover >= 0 ? static_cast<std::size_t>(o.rover) : mission.rover;
  try {
    sim::CheckRoverIndex(scenario, rover);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(o.mission_log + ": " + e.what());
  }
  const sim::TeamRovers team = sim::MakeTeamRovers(scenario, world);
  const sim::RoverTrajectory& trajectory = team.trajectories[rover];
  report << "  ground truth: rover " << rover << " (" << team.names[rover] << ") of "
         << scenario_name << ", seed " << seed << "\n";

  const Eigen::Isometry3d T_world_local0 = TrueFrameZero(mission, trajectory);

  std::map<uint32_t, Eigen::Isometry3d> origins = mapping::ReadFrameOrigins(o.mission_log);
  for (auto& [frame, T] : origins) T = T_world_local0 * T;

  MapResult r;
  PlaceAtGraphOrigins(o.mapd_logs, trajectory, mission, T_world_local0, o, &origins, &r, report);
  std::vector<mapping::SubmapLog> logs;
  uint64_t submap_bytes = 0;
  for (const std::string& path : o.mapd_logs) {
    logs.push_back(mapping::ReadSubmapLog(path));
    const mapping::SubmapLog& l = logs.back();
    report << "  mapd log " << path << ": " << l.submaps.size() << " submaps\n";
    for (const std::string& p : l.problems) report << "    problem: " << p << "\n";
    for (const mapping::LoggedSubmap& s : l.submaps) {
      submap_bytes += s.info.octree_bytes + s.info.cloud_bytes;
    }
    if (l.statistics.count("raw_stereo_bytes_per_s")) {
      r.raw_stereo_bytes_per_s =
          std::max(r.raw_stereo_bytes_per_s, std::stod(l.statistics.at("raw_stereo_bytes_per_s")));
    }
    r.submaps += l.submaps.size();
    if (l.statistics.count("matcher_ms_p50")) {
      r.matcher_ms_p50 = std::stod(l.statistics.at("matcher_ms_p50"));
    }
    if (l.statistics.count("graph_update_ms_p99")) {
      r.graph_update_ms_p99 = std::stod(l.statistics.at("graph_update_ms_p99"));
    }
  }
  mapping::MapComposer composer;
  const std::size_t unplaced = mapping::AddLoggedSubmaps(logs, origins, &composer);
  if (unplaced > 0) report << "  " << unplaced << " submaps in frames the mission never had\n";
  const auto start = std::chrono::steady_clock::now();
  const octomap::OcTree& map = composer.Compose();
  const mapping::PointCloud cloud = composer.ComposedCloud();
  r.compose_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (o.true_origins) ReportContentShift(world.terrain, logs, origins, report);
  r.map_memory_bytes = composer.Stats().octree_memory_bytes + composer.Stats().cloud_memory_bytes;
  const double duration_s = (mission.last_stamp - mission.init_stamp).ToSeconds();
  r.submap_bytes_per_s = duration_s > 0.0 ? static_cast<double>(submap_bytes) / duration_s : 0.0;

  sim::ObstacleRuleOptions rule;
  rule.rock_min_height_m = rule.step_height_m;  // rocks taller than a wheel climbs
  const sim::ObstacleGrid obstacles = sim::ComputeObstacleCells(world, rule);
  // The true (rectified) camera along the mapped part of the mission.
  std::vector<Eigen::Isometry3d> cameras;
  const RectifiedHead head = RectifiedHeadOf(scenario.camera);
  const Eigen::Isometry3d T_body_cam0 = head.T_body_cam0rect;
  AppendTrueCameras(mission, trajectory, T_body_cam0, &cameras);
  r.quality = EvaluateMap(world, obstacles, rule, map, cloud, cameras, head.stereo, o.quality);
  std::vector<log::rover_msgs::TagDetection> detections;
  for (const std::string& path : o.mapd_logs) {
    mapping::TagDetectionLog tags = mapping::ReadTagDetections(path);
    for (const std::string& p : tags.problems) report << "    tags: " << p << "\n";
    detections.insert(detections.end(), tags.detections.begin(), tags.detections.end());
  }
  r.tags = ScoreTagDetections(
      detections, world, [&](Time t) { return TrueCamera(mission, trajectory, T_body_cam0, t); });
  ReportTagScore(r.tags, report);
  if (!o.export_stem.empty()) {
    mapping::WriteOctreeBt(map, o.export_stem + ".bt");
    mapping::WritePly(cloud, o.export_stem + ".ply");
    report << "  world-frame map written to " << o.export_stem << ".bt and .ply\n";
  }
  const MapQuality& q = r.quality;
  report << "  composed " << r.submaps << " submaps in " << Num(r.compose_ms, 1) << " ms, "
         << Num(static_cast<double>(r.map_memory_bytes) / 1e6, 1) << " MB\n"
         << "  occupancy  precision " << Num(q.map_precision, 3) << " (" << q.occupied_on_surface
         << " of " << q.occupied_voxels << " occupied voxels on the true surface), recall "
         << Num(q.map_recall, 3) << " (" << q.observed_columns_hit << " of " << q.observed_columns
         << " observed columns)\n"
         << "  obstacles  precision " << Num(q.obstacle_precision, 3) << " ("
         << q.obstacle_points_true << " of " << q.obstacle_points << " flagged points), recall "
         << Num(q.obstacle_recall, 3) << " (" << q.truth_obstacle_cells_found << " of "
         << q.truth_obstacle_cells_observed << " observed obstacle cells)\n"
         << "  bandwidth  " << Num(r.submap_bytes_per_s / 1e3, 1) << " KB/s as submaps, "
         << Num(r.raw_stereo_bytes_per_s / 1e6, 2) << " MB/s raw stereo ("
         << Num(r.raw_stereo_bytes_per_s > 0.0
                    ? 100.0 * r.submap_bytes_per_s / r.raw_stereo_bytes_per_s
                    : std::numeric_limits<double>::quiet_NaN(),
                3)
         << " %)\n"
         << "  slam       final error " << Num(r.slam_final_error_m, 3) << " m ("
         << Num(r.slam_final_error_pct, 4) << " % of distance), " << r.loop_closures
         << " loop closures (" << r.loop_closures_valid << " within 0.2 m and 1 deg of the truth), "
         << r.graph_origins << " submaps at the graph's origins; match " << Num(r.matcher_ms_p50, 1)
         << " ms p50, graph update " << Num(r.graph_update_ms_p99, 1) << " ms p99\n";
  return r;
}

TeamMapResult EvaluateTeamMap(const std::vector<TeamMapRover>& rovers, std::ostream& report,
                              const MapQualityOptions& quality) {
  if (rovers.empty()) throw std::runtime_error("team map: no rovers");
  std::vector<MissionFacts> missions;
  // Each rover's frames chained by its switches (its frame 0 the identity).
  std::vector<std::map<uint32_t, Eigen::Isometry3d>> frames;
  for (const TeamMapRover& r : rovers) {
    missions.push_back(ReadMission(r.mission_log));
    frames.push_back(mapping::ReadFrameOrigins(r.mission_log));
  }
  const MissionFacts& first = missions.front();
  const sim::Scenario scenario = sim::LoadScenario(
      sim::FindScenario(sim::DefaultScenarioDir(), first.scenario), sim::DefaultSimConfigDir());
  const sim::World world = sim::World::Generate(scenario.world, first.seed);
  const sim::TeamRovers team = sim::MakeTeamRovers(scenario, world);
  std::vector<std::string> all_logs;
  for (const TeamMapRover& r : rovers) {
    all_logs.insert(all_logs.end(), r.mapd_logs.begin(), r.mapd_logs.end());
  }
  const mapping::TeamGraphSolution graph =
      mapping::SolveTeamGraph(mapping::ReadGraphLogs(all_logs));
  for (const std::string& p : graph.problems) report << "    team graph: " << p << "\n";
  // The anchor rover's frame 0 in the world, as for its own map.
  std::size_t anchor = rovers.size();
  for (std::size_t k = 0; k < rovers.size(); ++k) {
    if (static_cast<int>(missions[k].rover) == graph.anchor_robot) anchor = k;
  }
  if (anchor == rovers.size()) {
    throw std::runtime_error("team map: no mission log of robot " +
                             std::to_string(graph.anchor_robot) + ", whose prior anchors the team");
  }
  const MissionFacts& m0 = missions[anchor];
  const Eigen::Isometry3d T_world_local0 = TrueFrameZero(m0, team.trajectories[m0.rover]);
  const std::map<uint32_t, Eigen::Isometry3d>& frames0 = frames[anchor];
  // The anchor's prior frame: its lowest origin in the solution.
  int64_t prior_frame = -1;
  for (const auto& [key, T] : graph.origins) {
    if (key.first == graph.anchor_robot && (prior_frame < 0 || key.second < prior_frame)) {
      prior_frame = key.second;
    }
  }
  const auto chained = frames0.find(static_cast<uint32_t>(prior_frame));
  if (chained == frames0.end()) throw std::runtime_error("team map: the anchor's frame is unknown");
  const Eigen::Isometry3d T_world_graph =
      T_world_local0 * chained->second *
      graph.origins.at({graph.anchor_robot, prior_frame}).inverse();

  TeamMapResult r;
  r.unplaced_robots = graph.unplaced_robots;
  mapping::MapComposer composer;
  std::vector<Eigen::Isometry3d> cameras;
  const RectifiedHead head = RectifiedHeadOf(scenario.camera);
  uint32_t id = 0;
  std::vector<std::vector<mapping::SubmapLog>> kept(rovers.size());
  for (std::size_t k = 0; k < rovers.size(); ++k) {
    const int robot = static_cast<int>(missions[k].rover);
    std::map<uint32_t, Eigen::Isometry3d> origins;
    for (const auto& [key, T] : graph.origins) {
      if (key.first == robot) origins[static_cast<uint32_t>(key.second)] = T_world_graph * T;
    }
    for (const std::string& path : rovers[k].mapd_logs) {
      kept[k].push_back(mapping::ReadSubmapLog(path));
    }
    const mapping::SubmapPlacements placements = mapping::PlaceLoggedSubmaps(kept[k], origins);
    for (const mapping::SubmapLog& l : kept[k]) r.submaps += l.submaps.size();
    for (const mapping::SubmapPlacement& p : placements.placed) {
      const mapping::LoggedSubmap& s = kept[k][p.log].submaps[p.submap];
      composer.SetSubmap(id++, s.octree, s.cloud, p.T_map_submap);
      ++r.submaps_placed;
    }
    report << "  " << team.names[missions[k].rover] << " (robot " << robot
           << "): " << placements.placed.size() << " submaps placed, " << placements.unplaced.size()
           << " not";
    // Where the team put this rover's map against where it is: its frames'
    // true origins (its own frame 0 in the world, chained by its switches).
    const MissionFacts& m = missions[k];
    const Eigen::Isometry3d T_world_own0 = TrueFrameZero(m, team.trajectories[m.rover]);
    const std::map<uint32_t, Eigen::Isometry3d>& own_frames = frames[k];
    std::vector<double> errors_m, errors_deg;
    for (const auto& [frame, T_world_origin] : origins) {
      const auto t = own_frames.find(frame);
      if (t == own_frames.end()) continue;
      const Eigen::Isometry3d e = (T_world_own0 * t->second).inverse() * T_world_origin;
      errors_m.push_back(e.translation().norm());
      errors_deg.push_back(std::abs(YawOf(e.linear())) * 180.0 / M_PI);
    }
    if (!errors_m.empty()) {
      report << "; origins vs truth: median " << Num(stats::Percentile(errors_m, 50.0), 3) << " m, "
             << Num(stats::Percentile(errors_deg, 50.0), 2) << " deg (max "
             << Num(*std::max_element(errors_m.begin(), errors_m.end()), 3) << " m)";
    }
    report << "\n";
    AppendTrueCameras(m, team.trajectories[m.rover], head.T_body_cam0rect, &cameras);
  }
  const auto start = std::chrono::steady_clock::now();
  const octomap::OcTree& map = composer.Compose();
  const mapping::PointCloud cloud = composer.ComposedCloud();
  r.compose_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  sim::ObstacleRuleOptions rule;
  rule.rock_min_height_m = rule.step_height_m;  // as for one rover's map
  const sim::ObstacleGrid obstacles = sim::ComputeObstacleCells(world, rule);
  r.quality = EvaluateMap(world, obstacles, rule, map, cloud, cameras, head.stereo, quality);
  report << "  team map: " << r.submaps_placed << " of " << r.submaps << " submaps placed ("
         << graph.factors << " factors, " << graph.priors_left_out << " other priors left out, "
         << r.unplaced_robots.size() << " rovers unlinked); occupancy precision "
         << Num(r.quality.map_precision, 3) << ", recall " << Num(r.quality.map_recall, 3) << "\n";
  return r;
}

std::string MapResultFields(const MapResult& r) {
  const MapQuality& q = r.quality;
  return "map_precision=" + Num(q.map_precision, 4) + " map_recall=" + Num(q.map_recall, 4) +
         " obstacle_precision=" + Num(q.obstacle_precision, 4) +
         " obstacle_recall=" + Num(q.obstacle_recall, 4) + " submaps=" + std::to_string(r.submaps) +
         " submap_bytes_per_s=" + Num(r.submap_bytes_per_s, 0) +
         " raw_stereo_bytes_per_s=" + Num(r.raw_stereo_bytes_per_s, 0) +
         " loop_closures=" + std::to_string(r.loop_closures) +
         " loop_closure_precision=" + Num(r.loop_closure_precision, 3) +
         " matcher_ms_p50=" + Num(r.matcher_ms_p50, 1) +
         " graph_update_ms_p99=" + Num(r.graph_update_ms_p99, 1) +
         " frame_switch_nees=" + Num(r.frame_switch_nees, 2) +
         " tag_detections=" + std::to_string(r.tags.accepted) +
         " tag_factors=" + std::to_string(r.tag_factors) +
         " tag_nees_in_bound_pct=" + Num(r.tags.nees_in_bound_pct, 1) +
         " tag_flips_claimed=" + std::to_string(r.tags.wrong_solutions_claimed) +
         " slam_without_tags_err_pct=" + Num(r.slam_without_tags_error_pct, 4) +
         " team_factors=" + std::to_string(r.team_factors) +
         " slam_alone_err_pct=" + Num(r.slam_alone_error_pct, 4);
}

int RunMap(const MapCommandOptions& options, std::ostream& out, std::ostream& err) {
  try {
    out << "rover-sim map: " << options.mission_log << "\n";
    const MapResult r = EvaluateMission(options, out);
    out << "RESULT " << MapResultFields(r) << "\n";
    return kExitOk;
  } catch (const std::exception& e) {
    err << "rover-sim map: " << e.what() << "\n";
    return kExitBadInput;
  }
}

void AddObstacleScoringOptions(CLI::App* cmd, MapQualityOptions* quality) {
  cmd->add_option("--obstacle-radius-m", quality->obstacle_radius_m,
                  "a flagged point within this of a true obstacle cell is correct")
      ->capture_default_str();
  cmd->add_option("--obstacle-view-range-m", quality->obstacle_view_range_m,
                  "recall counts the true obstacles the camera saw from within this distance, "
                  "from where stereo resolves their height above a wheel's step")
      ->capture_default_str();
}

Subcommand AddMapCommand(CLI::App& app) {
  auto options = std::make_shared<MapCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "map",
      "quality of a simulated mission's map against the simulator's ground truth: occupied-voxel\n"
      "precision and recall against the true terrain surface, obstacle precision and recall\n"
      "against the true obstacle cells, and the submap bandwidth. Reads the mission log (frame\n"
      "switches, estimates, scenario, seed) and mapd's log(s) (submaps).");
  cmd->add_option("mission_log", options->mission_log, "the mission's flight log (roverd)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--mapd-log", options->mapd_logs, "mapd's log (repeat for a restarted mapd)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--scenario", options->scenario, "override the scenario recorded in the log");
  cmd->add_option("--seed", options->seed, "override the seed recorded in the log");
  cmd->add_option("--rover", options->rover,
                  "override the rover recorded in the log (0: the scenario's route, k: its k-th "
                  "other rover; logs without one are rover 0)");
  cmd->add_option("--export", options->export_stem,
                  "also write the world-frame map to STEM.bt (octovis) and STEM.ply");
  cmd->add_option("--surface-tolerance-m", options->quality.surface_tolerance_m,
                  "an occupied voxel within this of the true surface is correct")
      ->capture_default_str();
  AddObstacleScoringOptions(cmd, &options->quality);
  cmd->add_option("--false-matches", options->false_match_fraction,
                  "also re-solve mapd's graph with this share of its submap matches false "
                  "(tempting ones: near pairs, 1-4 m and up to 29 deg off), and report the final "
                  "error with and without them")
      ->check(CLI::Range(0.0, 0.9))
      ->capture_default_str();
  cmd->add_option("--false-match-seed", options->false_match_seed)->capture_default_str();
  cmd->add_flag("--rematch", options->rematch,
                "re-run loop closing offline on the logged submaps (mapd's pairing and matcher, "
                "every candidate matched before the next submap) and score that graph instead");
  cmd->add_flag("--rematch-reapply-switch-noise", options->rematch_reapply_switch_noise,
                "with --rematch: put the logged frame switches through the default noise model "
                "(logs written before mapd applied it)");
  cmd->add_option("--rematch-loop-config", options->rematch_loop_config,
                  "with --rematch: replay with the loop-closing options of this YAML file (keys "
                  "as mapd's loop section: data, pairing, matcher, max_queued_pairs, ...), to see "
                  "what another matcher setting would have found on the same submaps")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--explain-pairs", options->explain_pairs,
                "with --rematch: one line per pair of submaps whose obstacle boxes overlap at the "
                "true origins, saying whether it was matched or which pairing rule kept it out "
                "(unsuitable submap, overlap too small, relative sigma below the matcher's "
                "precision), to see which revisits loop closing missed and why")
      ->needs("--rematch");
  cmd->add_flag("--true-origins", options->true_origins,
                "diagnostic: compose the submaps at their true origins (the true body pose at "
                "each frame switch), to separate the submaps' own quality from the origins' error");
  cmd->add_option("--switch-sigma-scale", options->switch_sigma_scale,
                  "also re-solve mapd's graph with the frame switches' standard deviations "
                  "scaled by this (how much trusting the filter less would change)")
      ->check(CLI::Range(0.1, 100.0))
      ->capture_default_str();
  return {cmd, [options] { return RunMap(*options, std::cout, std::cerr); }};
}

}  // namespace rover::sim::experiments
