#include "hil/sim/experiments/loop_command.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>

#include "core/geometry/so3.h"
#include "core/geometry/yaw.h"
#include "firmware/mapd/local_mapper.h"
#include "hil/sim/motion/rover_trajectory.h"
#include "hil/sim/render/stereo_camera.h"
#include "hil/sim/render/stereo_renderer.h"
#include "hil/sim/scenario/scenario.h"
#include "hil/sim/world/world.h"
#include "mapping/loop/submap_icp.h"
#include "mapping/submap/submap.h"
#include "mapping/submap/submap_codec.h"

namespace rover::sim::experiments {

using cli::kExitBadInput;
using cli::kExitOk;
using cli::Subcommand;
namespace {

constexpr double kDeg = M_PI / 180.0;
/// chi-square 95 % quantile with 4 degrees of freedom (x, y, z, yaw).
constexpr double kChi2Four95 = 9.488;

std::string Num(double v, int digits) {
  if (!std::isfinite(v)) return "nan";
  char text[48];
  std::snprintf(text, sizeof(text), "%.*f", digits, v);
  return text;
}

double Median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

Eigen::Isometry3d BodyPose(const TrajectorySample& s) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = s.q_world_body.toRotationMatrix();
  T.translation() = s.p_world_body;
  return T;
}

// One submap of the drive: its frames and where the camera looked.
struct PlannedSubmap {
  Eigen::Isometry3d T_world_origin = Eigen::Isometry3d::Identity();
  std::vector<double> times_s;
  /// Ground the camera saw, roughly (1-4 m ahead, +-35 deg): to skip
  /// submaps that overlap nothing.
  Eigen::AlignedBox2d footprint;
};

std::vector<PlannedSubmap> PlanSubmaps(const RoverTrajectory& trajectory,
                                       const Eigen::Isometry3d& T_body_cam,
                                       const LoopCommandOptions& o) {
  std::vector<PlannedSubmap> plan;
  double driven = 0.0;
  Eigen::Vector2d last_xy = Eigen::Vector2d::Zero();
  for (double t = 0.0; t <= trajectory.duration_s(); t += o.frame_period_s) {
    const Eigen::Isometry3d T_world_body = BodyPose(trajectory.Evaluate(t));
    const Eigen::Vector2d xy = T_world_body.translation().head<2>();
    if (!plan.empty()) driven += (xy - last_xy).norm();
    last_xy = xy;
    if (plan.empty() || driven >= o.submap_length_m) {
      PlannedSubmap s;
      // The filter's local frame at the switch: gravity-aligned, at the body.
      s.T_world_origin =
          GravityAlignedTransform(T_world_body.translation(), YawOf(T_world_body.linear()));
      plan.push_back(s);
      driven = 0.0;
    }
    PlannedSubmap& s = plan.back();
    s.times_s.push_back(t);
    const Eigen::Isometry3d T_world_cam = T_world_body * T_body_cam;
    const Eigen::Vector3d forward = T_world_cam.linear().col(2);
    const double heading = std::atan2(forward.y(), forward.x());
    for (double range : {1.0, 4.0}) {
      for (double off : {-35.0, 0.0, 35.0}) {
        const double a = heading + off * kDeg;
        s.footprint.extend(xy + range * Eigen::Vector2d(std::cos(a), std::sin(a)));
      }
    }
  }
  return plan;
}

double OverlapArea(const Eigen::AlignedBox2d& a, const Eigen::AlignedBox2d& b) {
  if (a.isEmpty() || b.isEmpty()) return 0.0;
  const Eigen::AlignedBox2d i = a.intersection(b);
  return i.isEmpty() ? 0.0 : i.volume();
}

// The cache: the octree as .ot, the cloud as raw records (x, y, z float,
// obstacle byte).
std::string CacheStem(const LoopCommandOptions& o, uint64_t seed, int index) {
  return o.cache_dir + "/" + o.scenario + "_s" + std::to_string(seed) + "_p" +
         Num(o.frame_period_s, 3) + "_l" + Num(o.submap_length_m, 2) + "_" + std::to_string(index);
}

bool ReadCache(const std::string& stem, mapping::PointCloud* cloud,
               std::unique_ptr<octomap::OcTree>* tree) {
  std::ifstream ot(stem + ".ot", std::ios::binary);
  std::ifstream pc(stem + ".cloud", std::ios::binary);
  if (!ot || !pc) return false;
  std::stringstream bytes;
  bytes << ot.rdbuf();
  *tree = mapping::DecodeOctreeFull(bytes.str());
  cloud->clear();
  float xyz[3];
  char flag = 0;
  while (pc.read(reinterpret_cast<char*>(xyz), sizeof(xyz)) && pc.read(&flag, 1)) {
    cloud->push_back({Eigen::Vector3f(xyz[0], xyz[1], xyz[2]), flag != 0});
  }
  return true;
}

void WriteCache(const std::string& stem, const mapping::PointCloud& cloud,
                const octomap::OcTree& tree) {
  std::filesystem::create_directories(std::filesystem::path(stem).parent_path());
  std::ofstream(stem + ".ot", std::ios::binary) << mapping::EncodeOctreeFull(tree);
  std::ofstream pc(stem + ".cloud", std::ios::binary);
  for (const mapping::CloudPoint& c : cloud) {
    pc.write(reinterpret_cast<const char*>(c.p_submap_m.data()), 3 * sizeof(float));
    const char flag = c.obstacle ? 1 : 0;
    pc.write(&flag, 1);
  }
}

Eigen::AlignedBox2d WorldBox(const Eigen::AlignedBox2d& box, const Eigen::Isometry3d& T) {
  Eigen::AlignedBox2d out;
  if (box.isEmpty()) return out;
  for (int c = 0; c < 4; ++c) {
    const Eigen::Vector2d p = box.corner(static_cast<Eigen::AlignedBox2d::CornerType>(c));
    out.extend((T * Eigen::Vector3d(p.x(), p.y(), 0.0)).head<2>());
  }
  return out;
}

LoopMatchOutcome Score(const mapping::SubmapMatchResult& r, const mapping::SubmapMatchData& a,
                       const mapping::SubmapMatchData& b, const Eigen::Isometry3d& truth,
                       const LoopCommandOptions& o) {
  LoopMatchOutcome out;
  out.accepted = r.accepted;
  out.rejection = r.rejection;
  out.match_ms = r.timings.total_ms;
  out.correspondences = static_cast<int>(r.correspondences.size());
  out.inliers = static_cast<int>(r.inliers.size());
  out.icp_rmse_m = r.icp.rmse_m;
  out.overlap_ratio = r.overlap_ratio;
  out.obstacle_agreement = r.obstacle_agreement;
  for (const mapping::KeypointMatch& m : r.correspondences) {
    const Eigen::Vector3d pa = a.keypoints()[m.a].cast<double>();
    const Eigen::Vector3d pb = b.keypoints()[m.b].cast<double>();
    out.true_correspondences += (pa - truth * pb).norm() < 0.3;
  }
  // Errors in the covariance's convention: p_true = p_est + dp,
  // R_true = R_est Exp(dtheta).
  const Eigen::Vector3d dp = truth.translation() - r.T_a_b.translation();
  const Eigen::Vector3d dtheta = LogSO3(r.T_a_b.linear().transpose() * truth.linear());
  out.translation_error_m = dp.norm();
  out.error_m = dp;
  out.rotation_error_deg = dtheta.norm() / kDeg;
  out.yaw_error_deg =
      std::abs(std::remainder(YawOf(r.T_a_b.linear()) - YawOf(truth.linear()), 2 * M_PI)) / kDeg;
  out.inliers_on_a_line = r.inliers_on_a_line;
  out.icp_sigma_xy_m = std::sqrt(std::max(r.icp.covariance(0, 0), r.icp.covariance(1, 1)));
  out.icp_sigma_yaw_deg = std::sqrt(r.icp.covariance(5, 5)) / kDeg;
  out.initial_translation_error_m = (truth.translation() - r.T_a_b_initial.translation()).norm();
  out.initial_yaw_error_deg =
      std::abs(std::remainder(YawOf(r.T_a_b_initial.linear()) - YawOf(truth.linear()), 2 * M_PI)) /
      kDeg;
  out.valid = r.accepted && out.translation_error_m <= o.valid_translation_m &&
              out.rotation_error_deg <= o.valid_rotation_deg;
  if (r.accepted) {
    const int idx[4] = {0, 1, 2, 5};
    Eigen::Matrix4d cov;
    Eigen::Vector4d e;
    for (int i = 0; i < 4; ++i) {
      e(i) = i < 3 ? dp(i) : dtheta(2);
      for (int j = 0; j < 4; ++j) cov(i, j) = r.covariance(idx[i], idx[j]);
    }
    out.mahalanobis_sq = e.dot(cov.ldlt().solve(e));
  }
  return out;
}

std::string Describe(const LoopMatchOutcome& m) {
  return (m.accepted ? std::string(m.valid ? "valid" : "ACCEPTED-WRONG") : "rejected") + " " +
         Num(m.translation_error_m, 3) + " m (" + Num(m.error_m.x(), 3) + " " +
         Num(m.error_m.y(), 3) + " " + Num(m.error_m.z(), 3) + ") " + Num(m.yaw_error_deg, 2) +
         " deg, corr " + std::to_string(m.true_correspondences) + "/" +
         std::to_string(m.correspondences) + ", inliers " + std::to_string(m.inliers) + ", rmse " +
         Num(m.icp_rmse_m, 3) + ", overlap " + Num(m.overlap_ratio, 2) + ", obstacle agreement " +
         Num(m.obstacle_agreement, 2) + ", RANSAC " + Num(m.initial_translation_error_m, 3) +
         " m " + Num(m.initial_yaw_error_deg, 2) + " deg, ICP sigma " + Num(m.icp_sigma_xy_m, 4) +
         " m " + Num(m.icp_sigma_yaw_deg, 3) + " deg" + (m.inliers_on_a_line ? " (line)" : "") +
         ", " + Num(m.match_ms, 0) + " ms" + (m.accepted ? "" : " (" + m.rejection + ")");
}

struct Summary {
  int pairs = 0;
  int accepted = 0;
  int valid = 0;
  double precision = 0.0;
  double median_translation_m = 0.0;
  double median_yaw_deg = 0.0;
  double median_rotation_deg = 0.0;
  double consistent = 0.0;  ///< accepted with Mahalanobis^2 below the 95 % quantile
  double median_ms = 0.0;
  double max_ms = 0.0;
  double correspondence_precision = 0.0;  ///< median over pairs
};

Summary Summarise(const std::vector<LoopPairRecord>& records, bool four) {
  Summary s;
  std::vector<double> t, yaw, rot, ms, cp;
  int consistent = 0;
  for (const LoopPairRecord& r : records) {
    const LoopMatchOutcome& m = four ? r.four : r.six;
    ++s.pairs;
    ms.push_back(m.match_ms);
    s.max_ms = std::max(s.max_ms, m.match_ms);
    if (m.correspondences > 0) {
      cp.push_back(static_cast<double>(m.true_correspondences) / m.correspondences);
    }
    if (!m.accepted) continue;
    ++s.accepted;
    s.valid += m.valid;
    t.push_back(m.translation_error_m);
    yaw.push_back(m.yaw_error_deg);
    rot.push_back(m.rotation_error_deg);
    consistent += m.mahalanobis_sq <= kChi2Four95;
  }
  s.precision = s.accepted ? static_cast<double>(s.valid) / s.accepted : std::nan("");
  s.median_translation_m = Median(t);
  s.median_yaw_deg = Median(yaw);
  s.median_rotation_deg = Median(rot);
  s.consistent = s.accepted ? static_cast<double>(consistent) / s.accepted : std::nan("");
  s.median_ms = Median(ms);
  s.correspondence_precision = Median(cp);
  return s;
}

void PrintSummary(const char* label, const Summary& s, std::ostream& report) {
  report << "  " << label << ": accepted " << s.accepted << ", valid " << s.valid << " of "
         << s.pairs << " (precision " << Num(s.precision, 3) << "); accepted errors median "
         << Num(s.median_translation_m, 3) << " m, yaw " << Num(s.median_yaw_deg, 2)
         << " deg, rotation " << Num(s.median_rotation_deg, 2) << " deg; covariance consistent "
         << Num(s.consistent, 2) << "; correspondence precision "
         << Num(s.correspondence_precision, 3) << "; match " << Num(s.median_ms, 0)
         << " ms median, " << Num(s.max_ms, 0) << " max\n";
}

// One seed: plan, render and map the submaps that can pair, match pairs.
void EvaluateSeed(const Scenario& scenario, uint64_t seed, const LoopCommandOptions& o,
                  LoopResult* result, std::ostream& report) {
  const World world = World::Generate(scenario.world, seed);
  const RoverTrajectory trajectory(scenario.route, world.terrain);
  const Eigen::Isometry3d T_body_cam = scenario.camera.T_body_cam0;
  const std::vector<PlannedSubmap> plan = PlanSubmaps(trajectory, T_body_cam, o);
  result->submaps += static_cast<int>(plan.size());

  // Submaps whose footprints overlap a non-successive one's.
  std::set<int> needed;
  for (std::size_t i = 0; i < plan.size(); ++i) {
    for (std::size_t j = i + 2; j < plan.size(); ++j) {
      if (OverlapArea(plan[i].footprint, plan[j].footprint) > o.min_overlap_m2) {
        needed.insert(static_cast<int>(i));
        needed.insert(static_cast<int>(j));
      }
    }
  }
  report << "seed " << seed << ": " << plan.size() << " submaps over "
         << Num(trajectory.distance_m(), 0) << " m, " << needed.size() << " to build\n";

  std::unique_ptr<StereoRenderer> renderer;
  mapd::LocalMapper mapper({}, CameraModelOf(scenario.camera, scenario.camera.T_body_cam0),
                           CameraModelOf(scenario.camera, scenario.camera.T_body_cam1()));
  // Moving carriers (other rovers) are parked far away.
  std::vector<Eigen::Isometry3d> carriers;
  for (const TagCarrier& c : world.carriers) {
    if (!c.is_static) carriers.push_back(GravityAlignedTransform({1e3, 1e3, -1e3}, 0.0));
  }
  std::map<int, std::shared_ptr<const mapping::SubmapMatchData>> data;
  std::vector<double> data_ms;
  RenderedStereoFrame frame;
  uint64_t frame_index = 0;
  for (int i : needed) {
    const PlannedSubmap& p = plan[static_cast<std::size_t>(i)];
    mapping::PointCloud cloud;
    std::unique_ptr<octomap::OcTree> cached;
    const std::string stem = o.cache_dir.empty() ? "" : CacheStem(o, seed, i);
    mapping::Submap submap(static_cast<uint32_t>(i), static_cast<uint32_t>(i), {});
    if (stem.empty() || !ReadCache(stem, &cloud, &cached)) {
      if (!renderer) renderer = std::make_unique<StereoRenderer>(world, scenario.camera);
      mapper.ResetTraversability();
      for (double t : p.times_s) {
        const Eigen::Isometry3d T_world_body = BodyPose(trajectory.Evaluate(t));
        renderer->Render(T_world_body, carriers, seed * 1000003 + frame_index++, &frame);
        mapper.Process(frame.cam0, frame.cam1, p.T_world_origin.inverse() * T_world_body, &submap);
      }
      submap.Finish();
      cloud = submap.cloud();
      if (!stem.empty()) WriteCache(stem, cloud, submap.octree());
    }
    const octomap::OcTree& octree = cached ? *cached : submap.octree();
    std::vector<double> dz;
    for (const mapping::CloudPoint& c : cloud) {
      const Eigen::Vector3d w = p.T_world_origin * c.p_submap_m.cast<double>();
      dz.push_back(w.z() - world.terrain.HeightAt(w.x(), w.y()));
    }
    auto d = mapping::SubmapMatchData::Build(cloud, octree, o.data);
    data_ms.push_back(d->build_ms());
    ++result->submaps_built;
    result->submaps_suitable += d->suitable();
    report << "  submap " << i << ": " << p.times_s.size() << " images, " << d->suitability_reason()
           << " (" << Num(d->build_ms(), 0) << " ms); height above the true terrain: median "
           << Num(Median(dz), 3) << " m\n";
    data[i] = std::move(d);
  }
  result->data_ms_median = Median(data_ms);

  const mapping::SubmapMatcher four(o.matcher);
  mapping::SubmapMatcherOptions six_options = o.matcher;
  six_options.mode = mapping::MatchMode::kSixDof;
  const mapping::SubmapMatcher six(six_options);
  int pairs_this_seed = 0;
  for (auto ia = data.begin(); ia != data.end(); ++ia) {
    for (auto ib = std::next(ia); ib != data.end(); ++ib) {
      const int a = ia->first;
      const int b = ib->first;
      if (b == a + 1) continue;
      const Eigen::Isometry3d& T_wa = plan[static_cast<std::size_t>(a)].T_world_origin;
      const Eigen::Isometry3d& T_wb = plan[static_cast<std::size_t>(b)].T_world_origin;
      const double overlap = OverlapArea(WorldBox(ia->second->obstacle_box_xy(), T_wa),
                                         WorldBox(ib->second->obstacle_box_xy(), T_wb));
      if (!(overlap > o.min_overlap_m2)) continue;
      if (o.max_pairs_per_seed > 0 && pairs_this_seed >= o.max_pairs_per_seed) continue;
      ++pairs_this_seed;
      ++result->pairs;
      if (!ia->second->suitable() || !ib->second->suitable()) {
        report << "  pair " << a << "-" << b << ": overlap " << Num(overlap, 1)
               << " m^2, not matched (unsuitable)\n";
        continue;
      }
      ++result->pairs_matched;
      const Eigen::Isometry3d truth = T_wa.inverse() * T_wb;
      std::mt19937_64 rng(seed * 7919 + static_cast<uint64_t>(a) * 104729 +
                          static_cast<uint64_t>(b));
      std::normal_distribution<double> n(0.0, 1.0);
      mapping::MatchPrior prior;
      prior.T_a_b = truth;
      prior.T_a_b.translation() += o.prior_sigma_m * Eigen::Vector3d(n(rng), n(rng), n(rng));
      prior.T_a_b.linear() = truth.linear() * Rz(o.prior_sigma_yaw_deg * kDeg * n(rng));
      prior.covariance = mapping::Matrix6d::Zero();
      const double s2 = o.prior_sigma_m * o.prior_sigma_m;
      const double y2 = std::pow(o.prior_sigma_yaw_deg * kDeg, 2);
      prior.covariance.diagonal() << s2, s2, s2, 1e-4, 1e-4, y2;

      LoopPairRecord rec;
      rec.seed = seed;
      rec.a = a;
      rec.b = b;
      rec.overlap_m2 = overlap;
      rec.four =
          Score(four.Match(*ia->second, *ib->second, prior), *ia->second, *ib->second, truth, o);
      if (o.six_dof_baseline) {
        rec.six =
            Score(six.Match(*ia->second, *ib->second, prior), *ia->second, *ib->second, truth, o);
      }
      report << "  pair " << a << "-" << b << ": overlap " << Num(overlap, 1) << " m^2\n    4D "
             << Describe(rec.four) << "\n";
      if (o.truth_diagnostics) {
        const mapping::SubmapIcpResult t =
            mapping::AlignSubmaps(*ia->second, *ib->second, truth, true, o.matcher.icp);
        const std::size_t smaller =
            std::min(ia->second->icp_points().size(), ib->second->icp_points().size());
        const Eigen::Vector3d d = t.T_a_b.translation() - truth.translation();
        report << "    truth ICP: ok " << t.ok << ", moved " << Num(d.norm(), 3) << " m, rmse "
               << Num(t.rmse_m, 3) << ", overlap "
               << Num(static_cast<double>(t.overlap_points) /
                          static_cast<double>(std::max<std::size_t>(1, smaller)),
                      2)
               << ", obstacle agreement " << t.obstacle_points_agreeing << "/"
               << t.obstacle_points_near << ", sigma x y yaw "
               << Num(std::sqrt(t.covariance(0, 0)), 4) << " "
               << Num(std::sqrt(t.covariance(1, 1)), 4) << " "
               << Num(std::sqrt(t.covariance(5, 5)) / kDeg, 3) << " deg\n";
      }
      if (o.six_dof_baseline) report << "    6D " << Describe(rec.six) << "\n";
      result->records.push_back(rec);
    }
  }
}

}  // namespace

LoopResult EvaluateLoopClosures(const LoopCommandOptions& o, std::ostream& report) {
  if (!(o.frame_period_s > 0.0) || !(o.submap_length_m > 0.0)) {
    throw std::runtime_error("frame_period_s and submap_length_m must be > 0");
  }
  o.data.Validate();
  o.matcher.Validate();
  const Scenario scenario =
      LoadScenario(FindScenario(DefaultScenarioDir(), o.scenario), DefaultSimConfigDir());
  LoopResult result;
  for (uint64_t seed : o.seeds) {
    const std::size_t first = result.records.size();
    EvaluateSeed(scenario, seed, o, &result, report);
    const std::vector<LoopPairRecord> seed_records(
        result.records.begin() + static_cast<std::ptrdiff_t>(first), result.records.end());
    PrintSummary("seed 4D", Summarise(seed_records, true), report);
    if (o.six_dof_baseline) PrintSummary("seed 6D", Summarise(seed_records, false), report);
  }
  report << "overall: " << result.submaps << " submaps, " << result.submaps_built << " built, "
         << result.submaps_suitable << " suitable; " << result.pairs << " overlapping pairs, "
         << result.pairs_matched << " with both suitable; match data "
         << Num(result.data_ms_median, 0) << " ms median\n";
  PrintSummary("4D", Summarise(result.records, true), report);
  if (o.six_dof_baseline) PrintSummary("6D", Summarise(result.records, false), report);
  return result;
}

std::string LoopResultFields(const LoopResult& r) {
  const Summary s4 = Summarise(r.records, true);
  const Summary s6 = Summarise(r.records, false);
  return "pairs=" + std::to_string(r.pairs_matched) +
         " accepted_4d=" + std::to_string(s4.accepted) + " valid_4d=" + std::to_string(s4.valid) +
         " precision_4d=" + Num(s4.precision, 3) + " accepted_6d=" + std::to_string(s6.accepted) +
         " valid_6d=" + std::to_string(s6.valid) + " precision_6d=" + Num(s6.precision, 3) +
         " median_error_m_4d=" + Num(s4.median_translation_m, 3) +
         " median_yaw_deg_4d=" + Num(s4.median_yaw_deg, 2) +
         " median_match_ms_4d=" + Num(s4.median_ms, 0);
}

int RunLoop(const LoopCommandOptions& options, std::ostream& out, std::ostream& err) {
  try {
    out << "rover-sim loop: " << options.scenario << "\n";
    const LoopResult r = EvaluateLoopClosures(options, out);
    out << "RESULT " << LoopResultFields(r) << "\n";
    return kExitOk;
  } catch (const std::exception& e) {
    err << "rover-sim loop: " << e.what() << "\n";
    return kExitBadInput;
  }
}

Subcommand AddLoopCommand(CLI::App& app) {
  auto options = std::make_shared<LoopCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "loop",
      "the submap matcher (mapping/loop) on submaps mapped from rendered stereo along a\n"
      "scenario's route: every overlapping pair of non-successive submaps matched in 4D and\n"
      "6D with a noisy prior; valid matches, precision, median errors against ground truth.");
  cmd->add_option("--scenario", options->scenario, "scenario name")->capture_default_str();
  cmd->add_option("--seeds", options->seeds, "world seeds")->capture_default_str();
  cmd->add_option("--submap-length-m", options->submap_length_m, "driving per submap")
      ->capture_default_str();
  cmd->add_option("--frame-period-s", options->frame_period_s, "one image every")
      ->capture_default_str();
  cmd->add_option("--prior-sigma-m", options->prior_sigma_m, "prior noise, translation")
      ->capture_default_str();
  cmd->add_option("--prior-sigma-yaw-deg", options->prior_sigma_yaw_deg, "prior noise, yaw")
      ->capture_default_str();
  cmd->add_option("--max-pairs", options->max_pairs_per_seed, "per seed, 0: all")
      ->capture_default_str();
  cmd->add_option("--descriptor-radius-m", options->data.descriptor.radius_m)
      ->capture_default_str();
  cmd->add_option("--max-descriptor-distance", options->matcher.max_descriptor_distance)
      ->capture_default_str();
  cmd->add_flag(
      "--oriented-descriptor",
      [options](int64_t) {
        options->data.descriptor.kind = mapping::GravityDescriptorKind::kOriented;
      },
      "SHOT-like sectors from the yaw reference instead of Fourier magnitudes");
  cmd->add_flag(
      "--point-to-point",
      [options](int64_t) { options->matcher.icp.metric = mapping::IcpMetric::kPointToPoint; },
      "point-to-point ICP instead of point-to-plane");
  cmd->add_option("--hough-bin-m", options->matcher.hough_bin_m)->capture_default_str();
  cmd->add_option("--cache-dir", options->cache_dir,
                  "keep built submaps here and reuse them (same scenario, seed, planning)");
  cmd->add_option("--min-known-ratio", options->data.min_known_ratio)->capture_default_str();
  cmd->add_option("--max-normal-angle-deg", options->matcher.icp.max_normal_angle_deg,
                  "ICP normal compatibility, 180: off")
      ->capture_default_str();
  cmd->add_flag(
      "--gravity-normals",
      [options](int64_t) { options->data.orient_normals_to_free_space = false; },
      "all normals up instead of towards the voxel space's free side");
  cmd->add_flag(
      "--no-6d", [options](int64_t) { options->six_dof_baseline = false; }, "skip the 6D baseline");
  cmd->add_option("--icp-robust-scale-m", options->matcher.icp.robust_scale_m)
      ->capture_default_str();
  cmd->add_option("--icp-final-distance-m", options->matcher.icp.final_distance_m)
      ->capture_default_str();
  cmd->add_option("--icp-voxel-m", options->data.icp_voxel_m)->capture_default_str();
  cmd->add_option("--min-obstacle-agreement", options->matcher.min_obstacle_agreement)
      ->capture_default_str();
  cmd->add_option("--min-sigma-m", options->matcher.min_sigma_m)->capture_default_str();
  cmd->add_option("--rmse-sigma-factor", options->matcher.rmse_sigma_factor)->capture_default_str();
  cmd->add_flag(
      "--truth-diagnostics", [options](int64_t) { options->truth_diagnostics = true; },
      "also run the 4D ICP from the true transform and print its checks");
  cmd->add_option("--min-obstacle-points", options->data.min_obstacle_points)
      ->capture_default_str();
  cmd->add_option("--min-keypoints-off-line", options->data.min_keypoints_off_line)
      ->capture_default_str();
  cmd->add_option("--min-inliers-off-line", options->matcher.min_inliers_off_line)
      ->capture_default_str();
  cmd->add_option("--min-inliers", options->matcher.min_inliers)->capture_default_str();
  cmd->add_option("--max-line-icp-sigma-m", options->matcher.max_line_icp_sigma_m)
      ->capture_default_str();
  cmd->add_option("--max-line-icp-sigma-yaw-rad", options->matcher.max_line_icp_sigma_yaw_rad)
      ->capture_default_str();
  cmd->add_option("--max-icp-rmse-m", options->matcher.max_icp_rmse_m)->capture_default_str();
  cmd->add_option("--min-overlap-ratio", options->matcher.min_overlap_ratio)->capture_default_str();
  cmd->add_option("--min-sigma-yaw-rad", options->matcher.min_sigma_yaw_rad)->capture_default_str();
  return {cmd, [options] { return RunLoop(*options, std::cout, std::cerr); }};
}

}  // namespace rover::sim::experiments
