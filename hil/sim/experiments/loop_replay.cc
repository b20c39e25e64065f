#include "hil/sim/experiments/loop_replay.h"

#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "core/geometry/yaw.h"
#include "mapping/graph/rover_graph.h"
#include "mapping/loop/submap_matcher.h"
#include "mapping/loop/submap_pairing.h"

namespace rover::sim::experiments {
namespace {

mapping::GraphFactorRecord WithSwitchNoise(const mapping::GraphFactorRecord& w,
                                           const mapping::FrameSwitchNoiseOptions& noise) {
  mapping::GraphFactorRecord out = mapping::FrameSwitchFactor(
      w.a.robot, w.a.index, w.T_a_b.translation(), YawOf(w.T_a_b.linear()),
      mapping::FrameSwitchCovariance(mapping::FourDofBlock(w.covariance), w.T_a_b.translation(),
                                     noise));
  out.id = w.id;
  out.stamp_ns = w.stamp_ns;
  return out;
}

// The replay's state: graph, pairing, matcher and the submaps' data.
class Replay {
 public:
  Replay(const LoopReplayOptions& options, std::ostream& report)
      : options_(options),
        report_(report),
        pairing_(options.loop.pairing),
        matcher_(options.loop.matcher) {}

  void Add(const mapping::GraphFactorRecord& f) {
    mapping::AddToGraph(f, &graph_);
    factors_.push_back(f);
    if (f.kind == mapping::FactorKind::kPrior) robot_ = f.a.robot;
  }

  // Submap `frame` is finished: its data joins the pairing, then every
  // candidate pair is matched.
  void Finish(int64_t frame, const mapping::LoggedSubmap* submap) {
    graph_.Optimize();
    UpdateOrigins();
    if (submap != nullptr) AddToPairing(frame, *submap);
    while (std::optional<mapping::SubmapPair> pair = pairing_.Next()) Match(*pair);
  }

  // One line per pair whose obstacle boxes overlap at the true origins.
  void ExplainPairs() {
    int explained = 0;
    for (auto ia = data_.begin(); ia != data_.end(); ++ia) {
      for (auto ib = std::next(ia); ib != data_.end(); ++ib) {
        if (ExplainPair(ia->first, *ia->second, ib->first, *ib->second)) ++explained;
      }
    }
    report_ << "    pairs: " << explained
            << " pairs of non-successive submaps overlap at the true origins\n";
  }

  mapping::RoverGraph& graph() { return graph_; }
  std::vector<mapping::GraphFactorRecord>& factors() { return factors_; }
  LoopReplayResult& result() { return result_; }

 private:
  void UpdateOrigins() {
    for (const auto& [frame, data] : data_) {
      pairing_.UpdateOrigin({robot_, frame}, graph_.Origin(robot_, frame),
                            graph_.OriginCovariance(robot_, frame));
    }
  }

  // T_a_b between the true origins of the pair, when both are known.
  std::optional<Eigen::Isometry3d> TrueTransform(const mapping::SubmapPair& pair) const {
    const auto a = options_.true_origins.find(pair.a.index);
    const auto b = options_.true_origins.find(pair.b.index);
    if (a == options_.true_origins.end() || b == options_.true_origins.end()) return std::nullopt;
    return a->second.inverse() * b->second;
  }

  // The result's and the prior's error against the truth, for the report.
  static std::string TruthError(const mapping::SubmapPair& pair,
                                const mapping::SubmapMatchResult& r,
                                const Eigen::Isometry3d& T_true) {
    const Eigen::Isometry3d error = T_true.inverse() * r.T_a_b;
    const Eigen::Isometry3d prior_error = T_true.inverse() * pair.prior.T_a_b;
    const double prior_sigma_xy_m =
        std::sqrt(std::max(pair.prior.covariance(0, 0), pair.prior.covariance(1, 1)));
    const double prior_sigma_yaw_deg = std::sqrt(pair.prior.covariance(5, 5)) * 180.0 / M_PI;
    char text[200];
    std::snprintf(
        text, sizeof(text), " (vs truth: %.3f m %.2f deg; prior %.3f m off, sigma %.3f m %.2f deg)",
        error.translation().norm(), Eigen::AngleAxisd(error.linear()).angle() * 180.0 / M_PI,
        prior_error.translation().norm(), prior_sigma_xy_m, prior_sigma_yaw_deg);
    return text;
  }

  void AddToPairing(int64_t frame, const mapping::LoggedSubmap& submap) {
    if (!submap.cloud || !submap.octree) return;
    std::shared_ptr<const mapping::SubmapMatchData> data;
    try {
      data = mapping::SubmapMatchData::Build(*submap.cloud, *submap.octree, options_.loop.data);
    } catch (const std::exception& e) {
      report_ << "    replay: submap " << frame << " has no matching data: " << e.what() << "\n";
      return;
    }
    if (data->suitable()) ++result_.submaps_suitable;
    pairing_.AddSubmap({robot_, frame}, *data, graph_.Origin(robot_, frame),
                       graph_.OriginCovariance(robot_, frame));
    data_[frame] = data;
  }

  void Match(const mapping::SubmapPair& pair) {
    const auto a = data_.find(pair.a.index);
    const auto b = data_.find(pair.b.index);
    if (a == data_.end() || b == data_.end()) return;
    const mapping::SubmapMatchResult r = matcher_.Match(*a->second, *b->second, pair.prior);
    ++result_.pairs_matched;
    const Eigen::Isometry3d correction = pair.prior.T_a_b.inverse() * r.T_a_b;
    const std::optional<Eigen::Isometry3d> T_true = TrueTransform(pair);
    char line[1024];
    std::snprintf(
        line, sizeof(line),
        "    replay: %lld-%lld %s%s, %.2f m %.2f deg from the graph, overlap %.2f, obstacle "
        "agreement %.2f, %d inliers, ICP rmse %.3f m, s^2 H^-1 sigma %.4f m %.3f deg%s\n",
        static_cast<long long>(pair.a.index), static_cast<long long>(pair.b.index),
        r.accepted ? (r.from_prior ? "accepted from the prior" : "accepted") : "rejected: ",
        r.rejection.c_str(), correction.translation().norm(),
        std::abs(YawOf(correction.linear())) * 180.0 / M_PI, r.overlap_ratio, r.obstacle_agreement,
        static_cast<int>(r.inliers.size()), r.icp.rmse_m,
        std::sqrt(r.icp.covariance(0, 0) + r.icp.covariance(1, 1)),
        std::sqrt(r.icp.covariance(5, 5)) * 180.0 / M_PI,
        T_true ? TruthError(pair, r, *T_true).c_str() : "");
    report_ << line;
    outcome_[{std::min(pair.a.index, pair.b.index), std::max(pair.a.index, pair.b.index)}] =
        r.accepted ? "matched: accepted" : "matched: rejected (" + r.rejection + ")";
    if (!r.accepted) return;
    ++result_.matches_accepted;
    if (T_true && IsValidLoopClosure(r.T_a_b, *T_true)) ++result_.matches_valid;
    mapping::GraphFactorRecord c = mapping::SubmapMatchFactor(
        mapping::GraphKey::Origin(pair.a.robot, pair.a.index),
        mapping::GraphKey::Origin(pair.b.robot, pair.b.index), r.T_a_b, r.covariance);
    Add(c);
    graph_.Optimize();
    UpdateOrigins();
  }

  bool ExplainPair(int64_t a, const mapping::SubmapMatchData& data_a, int64_t b,
                   const mapping::SubmapMatchData& data_b) {
    const auto true_a = options_.true_origins.find(a);
    const auto true_b = options_.true_origins.find(b);
    if (true_a == options_.true_origins.end() || true_b == options_.true_origins.end()) {
      return false;
    }
    const double true_overlap_m2 = mapping::ObstacleBoxOverlapM2(
        data_a.obstacle_box_xy(), true_a->second, data_b.obstacle_box_xy(), true_b->second);
    if (true_overlap_m2 <= 0.0) return false;
    const mapping::PairVerdict verdict = pairing_.Check({robot_, a}, {robot_, b});
    if (verdict == mapping::PairVerdict::kSuccessive) return false;  // not a revisit
    const mapping::SubmapPair pair = pairing_.Evaluate({robot_, a}, {robot_, b});
    const auto matched = outcome_.find({a, b});
    char line[512];
    std::snprintf(
        line, sizeof(line),
        "    pair %lld-%lld: true obstacle-box overlap %.1f m^2; %s; overlap' %.1f m^2 "
        "(min %.1f), relative sigma %.3f m (matcher precision %.3f m)\n",
        static_cast<long long>(a), static_cast<long long>(b), true_overlap_m2,
        matched != outcome_.end() ? matched->second.c_str() : mapping::PairVerdictName(verdict),
        pair.overlap_m2, options_.loop.pairing.min_overlap_m2, pair.relative_sigma_m.mean(),
        options_.loop.pairing.MatcherPrecisionM());
    report_ << line;
    return true;
  }

  const LoopReplayOptions& options_;
  std::ostream& report_;
  /// "matched: accepted" / "matched: rejected (...)" by pair, for ExplainPairs.
  std::map<std::pair<int64_t, int64_t>, std::string> outcome_;
  mapping::RoverGraph graph_;
  mapping::SubmapPairing pairing_;
  mapping::SubmapMatcher matcher_;
  std::vector<mapping::GraphFactorRecord> factors_;
  std::map<int64_t, std::shared_ptr<const mapping::SubmapMatchData>> data_;
  int robot_ = 0;
  LoopReplayResult result_;
};

// The replayed graph's origins, and the logged final pose moved with its
// frame's origin.
void FinalEstimates(const mapping::GraphLogContents& logged, const mapping::RoverGraph& graph,
                    mapping::GraphLogContents* out) {
  out->last_origins = logged.last_origins;
  for (log::rover_msgs::SubmapOrigin& o : out->last_origins->origins) {
    o.pose = mapping::ToPoseMsg(graph.Origin(o.robot, o.submap));
  }
  if (!logged.last_global_pose) return;
  out->last_global_pose = logged.last_global_pose;
  out->last_global_pose->pose.pose =
      mapping::ToPoseMsg(mapping::MovedFinalGlobalPose(logged, graph));
}

}  // namespace

bool IsValidLoopClosure(const Eigen::Isometry3d& T_a_b, const Eigen::Isometry3d& T_a_b_true) {
  const Eigen::Isometry3d error = T_a_b_true.inverse() * T_a_b;
  return error.translation().norm() <= kValidLoopClosureTranslationM &&
         Eigen::AngleAxisd(error.linear()).angle() <= kValidLoopClosureRotationDeg * M_PI / 180.0;
}

LoopReplayResult ReplayLoopClosing(const mapping::GraphLogContents& logged,
                                   const mapping::SubmapLog& submaps,
                                   const LoopReplayOptions& options, std::ostream& report) {
  if (!logged.last_origins || logged.last_origins->origins.empty()) {
    throw std::runtime_error("loop replay: the mapd log has no optimised origins");
  }
  std::map<int64_t, const mapping::LoggedSubmap*> by_frame;
  for (const mapping::LoggedSubmap& s : submaps.submaps) by_frame[s.info.frame_id] = &s;
  Replay replay(options, report);
  bool has_prior = false;
  for (const mapping::GraphFactorRecord& f : logged.factors) {
    if (f.kind == mapping::FactorKind::kPrior) {
      replay.Add(f);
      has_prior = true;
    } else if (f.kind == mapping::FactorKind::kFrameSwitch && has_prior) {
      replay.Add(options.reapply_switch_noise ? WithSwitchNoise(f, options.switch_noise) : f);
      const auto submap = by_frame.find(f.a.index);
      replay.Finish(f.a.index, submap == by_frame.end() ? nullptr : submap->second);
    }
  }
  if (!has_prior) throw std::runtime_error("loop replay: the mapd log's graph has no prior");
  replay.graph().Optimize();
  if (options.explain_pairs) replay.ExplainPairs();
  LoopReplayResult result = replay.result();
  result.graph.factors = replay.factors();
  FinalEstimates(logged, replay.graph(), &result.graph);
  return result;
}

}  // namespace rover::sim::experiments
