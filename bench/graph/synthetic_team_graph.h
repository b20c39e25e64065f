#ifndef ROVER_BENCH_GRAPH_SYNTHETIC_TEAM_GRAPH_H_
#define ROVER_BENCH_GRAPH_SYNTHETIC_TEAM_GRAPH_H_

// A seeded synthetic multi-robot submap-origin graph for bench_team_graph:
// R robots each drive a chain of gravity-aligned submap origins (5-7 m apart)
// over gentle terrain; consecutive origins are linked by 6-DoF odometry with
// ~1 % translation noise, a few percent of the origins close a loop with an
// earlier origin of the same robot, and wherever two robots' routes come
// within `meet_radius_m` of each other the generator may add an inter-robot
// submap match. Meeting places are geometric: in the shared-area layout
// every pair of robots meets; in the neighbouring-areas layout robot r's area
// overlaps only those of r - 1 and r + 1, so only neighbours meet.
//
// The graph goes out as a g2o PoseGraph (vertex id = robot * submaps + submap;
// the first vertex, robot 0's first origin, is the gauge: it plays the prior)
// for SolvePoseGraph and HelmertBlockSolver, and as RoverGraph factors
// (prior on robot 0's first origin, odometry as AddBetween, matches as
// AddSubmapMatch) for the online path. Header-only: nothing in mapping/
// depends on it.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "core/geometry/so3.h"
#include "core/geometry/yaw.h"
#include "mapping/graph/pose_graph.h"
#include "mapping/graph/rover_graph.h"

namespace rover::mapping {

enum class TeamLayout {
  kSharedArea,      ///< All robots explore one area from a common start: every pair meets.
  kNeighbourAreas,  ///< Robot r explores its own area, overlapping only r - 1 and r + 1.
};

struct SyntheticTeamGraphOptions {
  int robots = 3;
  int submaps_per_robot = 300;
  double step_min_m = 5.0;  ///< Travel between consecutive origins, uniform in [min, max].
  double step_max_m = 7.0;
  double area_width_m = 150.0;  ///< Side of each robot's (square) area.
  TeamLayout layout = TeamLayout::kSharedArea;
  /// Neighbouring areas: the fraction of the width two neighbours share.
  double neighbour_overlap = 0.25;
  /// Odometry noise per axis: translation as a fraction of the step, yaw, and
  /// roll/pitch (origins are gravity-aligned, so those stay small).
  double odometry_sigma_fraction = 0.01;
  double odometry_yaw_sigma_rad = 0.1 * std::numbers::pi / 180.0;
  double odometry_roll_pitch_sigma_rad = 0.01 * std::numbers::pi / 180.0;
  /// Submap match noise (intra- and inter-robot), per axis.
  double match_sigma_m = 0.05;
  double match_yaw_sigma_rad = 0.2 * std::numbers::pi / 180.0;
  double match_roll_pitch_sigma_rad = 0.05 * std::numbers::pi / 180.0;
  /// Two origins closer than this are a place where a match can be found.
  double meet_radius_m = 4.0;
  /// Intra-robot loop closures per robot, as a fraction of its origins.
  double intra_loop_fraction = 0.03;
  int min_loop_gap = 20;  ///< Intra-robot matches span at least this many origins.
  /// Inter-robot matches per pair of robots that meet (fewer if they meet at
  /// fewer distinct places).
  int inter_closures_per_pair = 15;
  /// Chosen matches of one pair are at least this many origins apart on
  /// either robot (distinct places, not one crossing counted many times).
  int min_place_gap = 5;
};

struct TeamMatch {
  int robot_a = 0;
  int64_t submap_a = 0;
  int robot_b = 0;
  int64_t submap_b = 0;
  Eigen::Isometry3d T_a_b = Eigen::Isometry3d::Identity();  ///< Measured, noisy.
  Matrix6d covariance = Matrix6d::Identity();               ///< [dp (frame a); dtheta (right)].
};

struct SyntheticTeamGraph {
  int robots = 0;
  int submaps = 0;                                             ///< Per robot.
  std::vector<std::vector<Eigen::Isometry3d>> T_world_origin;  ///< Truth [robot][submap].
  std::vector<std::vector<Eigen::Isometry3d>> odometry;        ///< Measured T_i_i+1 [robot][i].
  std::vector<std::vector<Matrix6d>> odometry_covariance;
  std::vector<TeamMatch> intra;  ///< Same-robot loop closures.
  std::vector<TeamMatch> inter;  ///< Inter-robot matches in the graph.
  /// Further meeting places (not in the graph), in the order found: the
  /// "what changed" updates add them one at a time.
  std::vector<TeamMatch> spare_inter;

  int64_t VertexId(int robot, int64_t submap) const {
    return static_cast<int64_t>(robot) * submaps + submap;
  }

  /// Edges: odometry, then intra-robot, then inter-robot matches. Vertex 0
  /// (robot 0's first origin) at its true pose; the others at the identity,
  /// for an initialisation to replace.
  PoseGraph ToPoseGraph() const {
    PoseGraph g;
    g.dimension = 3;
    g.source = "synthetic team graph";
    for (int r = 0; r < robots; ++r) {
      for (int i = 0; i < submaps; ++i) {
        PoseVertex v;
        v.id = VertexId(r, i);
        if (r == 0 && i == 0) v.pose = T_world_origin[0][0];
        g.vertices.push_back(v);
      }
    }
    for (int r = 0; r < robots; ++r) {
      for (int i = 0; i + 1 < submaps; ++i) {
        const Eigen::Isometry3d& Z = odometry[static_cast<size_t>(r)][static_cast<size_t>(i)];
        g.edges.push_back(
            Edge(VertexId(r, i), VertexId(r, i + 1), Z,
                 odometry_covariance[static_cast<size_t>(r)][static_cast<size_t>(i)]));
      }
    }
    for (const std::vector<TeamMatch>* list : {&intra, &inter}) {
      for (const TeamMatch& m : *list) g.edges.push_back(ToEdge(m));
    }
    return g;
  }

  PoseEdge ToEdge(const TeamMatch& m) const {
    return Edge(VertexId(m.robot_a, m.submap_a), VertexId(m.robot_b, m.submap_b), m.T_a_b,
                m.covariance);
  }

  /// One block per robot, in ToPoseGraph()'s vertex order.
  std::vector<int> RobotOfVertex() const {
    std::vector<int> block;
    for (int r = 0; r < robots; ++r) block.insert(block.end(), static_cast<size_t>(submaps), r);
    return block;
  }

  /// The same graph as RoverGraph factors: a tight prior on s0_0 at its true
  /// pose, odometry (non-robust), matches (robust, as mapd adds them).
  void AddTo(RoverGraph* graph) const {
    graph->AddOriginPrior(0, T_world_origin[0][0], 1e-8 * Matrix6d::Identity());
    for (int r = 0; r < robots; ++r) {
      for (int i = 0; i + 1 < submaps; ++i) {
        graph->AddBetween(GraphKey::Origin(r, i), GraphKey::Origin(r, i + 1),
                          odometry[static_cast<size_t>(r)][static_cast<size_t>(i)],
                          odometry_covariance[static_cast<size_t>(r)][static_cast<size_t>(i)],
                          false);
      }
    }
    for (const std::vector<TeamMatch>* list : {&intra, &inter}) {
      for (const TeamMatch& m : *list) AddTo(m, graph);
    }
  }

  static void AddTo(const TeamMatch& m, RoverGraph* graph) {
    graph->AddSubmapMatch(m.robot_a, m.submap_a, m.robot_b, m.submap_b, m.T_a_b, m.covariance);
  }

 private:
  static PoseEdge Edge(int64_t from, int64_t to, const Eigen::Isometry3d& Z, const Matrix6d& cov) {
    PoseEdge e;
    e.from = from;
    e.to = to;
    e.measurement = Z;
    e.information = InformationFromCovariance(Z, cov);
    return e;
  }
};

namespace synthetic_team_detail {

using Vector6d = Eigen::Matrix<double, 6, 1>;

inline double TerrainHeightM(double x_m, double y_m) {
  return 2.0 * std::sin(x_m / 35.0) * std::cos(y_m / 45.0);
}

// A measurement of T_true with noise of standard deviations sigma over
// [dp (frame a); dtheta (right)], in RoverGraph's convention
// p_true = p_est + dp, R_true = R_est Exp(dtheta).
inline Eigen::Isometry3d Noisy(const Eigen::Isometry3d& T_true, const Vector6d& sigma,
                               std::mt19937& rng) {
  std::normal_distribution<double> n01(0.0, 1.0);
  Vector6d e;
  for (int k = 0; k < 6; ++k) e(k) = sigma(k) * n01(rng);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = T_true.translation() - e.head<3>();
  T.linear() = T_true.linear() * ExpSO3(-e.tail<3>());
  return T;
}

// Matches between robots a and b (a == b: loop closures of one robot at
// least min_loop_gap apart): every pair of origins within meet_radius_m, in
// random order, keeping those at least min_place_gap from an already kept
// one on either robot. The first `wanted` go to `out` and up to `wanted`
// more to `spare` (if given); where the robots meet at fewer places, two of
// them (one if they meet at two) are kept back as spares, so that every pair
// that meets can be given a new match later.
inline void FindMatches(const SyntheticTeamGraphOptions& o, const SyntheticTeamGraph& g, int a,
                        int b, int wanted, std::mt19937& rng, std::vector<TeamMatch>* out,
                        std::vector<TeamMatch>* spare) {
  const auto& A = g.T_world_origin[static_cast<size_t>(a)];
  const auto& B = g.T_world_origin[static_cast<size_t>(b)];
  std::vector<std::pair<int, int>> candidates;
  for (int i = 0; i < g.submaps; ++i) {
    for (int j = a == b ? i + o.min_loop_gap : 0; j < g.submaps; ++j) {
      if ((A[static_cast<size_t>(i)].translation() - B[static_cast<size_t>(j)].translation())
              .norm() < o.meet_radius_m) {
        candidates.emplace_back(i, j);
      }
    }
  }
  std::shuffle(candidates.begin(), candidates.end(), rng);
  Vector6d sigma;
  sigma << o.match_sigma_m, o.match_sigma_m, o.match_sigma_m, o.match_roll_pitch_sigma_rad,
      o.match_roll_pitch_sigma_rad, o.match_yaw_sigma_rad;
  const Matrix6d covariance = sigma.cwiseAbs2().asDiagonal();
  std::vector<std::pair<int, int>> kept;
  const int limit = spare != nullptr ? 2 * wanted : wanted;
  for (const auto& [i, j] : candidates) {
    if (static_cast<int>(kept.size()) >= limit) break;
    const bool distinct = std::all_of(kept.begin(), kept.end(), [&](const auto& k) {
      return std::abs(k.first - i) >= o.min_place_gap || std::abs(k.second - j) >= o.min_place_gap;
    });
    if (distinct) kept.emplace_back(i, j);
  }
  const int places = static_cast<int>(kept.size());
  const int in_graph =
      spare == nullptr ? places : std::min(wanted, places - std::min(2, places / 2));
  for (int k = 0; k < places; ++k) {
    const auto [i, j] = kept[static_cast<size_t>(k)];
    TeamMatch m;
    m.robot_a = a;
    m.submap_a = i;
    m.robot_b = b;
    m.submap_b = j;
    m.T_a_b = Noisy(A[static_cast<size_t>(i)].inverse() * B[static_cast<size_t>(j)], sigma, rng);
    m.covariance = covariance;
    (k < in_graph ? out : spare)->push_back(m);
  }
}

}  // namespace synthetic_team_detail

/// Builds the team graph; identical for identical (options, seed). Throws
/// GraphError if a robot meets no other robot (its chain would float).
inline SyntheticTeamGraph MakeSyntheticTeamGraph(const SyntheticTeamGraphOptions& o,
                                                 uint32_t seed) {
  using synthetic_team_detail::Vector6d;
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  SyntheticTeamGraph g;
  g.robots = o.robots;
  g.submaps = o.submaps_per_robot;
  const double W = o.area_width_m;
  for (int r = 0; r < o.robots; ++r) {
    // Area [x0, x0 + W] x [0, W]; shared: one area, the robots start a few
    // metres apart near its centre (deployed together).
    const double x0 =
        o.layout == TeamLayout::kSharedArea ? 0.0 : r * (1.0 - o.neighbour_overlap) * W;
    const Eigen::Vector2d centre(x0 + 0.5 * W, 0.5 * W);
    Eigen::Vector2d p = centre;
    if (o.layout == TeamLayout::kSharedArea) p += Eigen::Vector2d(3.0 * r, 0.0);
    double yaw = 2.0 * std::numbers::pi * unit(rng);
    std::vector<Eigen::Isometry3d>& truth = g.T_world_origin.emplace_back();
    std::vector<double> steps_m;
    for (int i = 0; i < o.submaps_per_robot; ++i) {
      truth.push_back(GravityAlignedTransform(
          Eigen::Vector3d(p.x(), p.y(), synthetic_team_detail::TerrainHeightM(p.x(), p.y())), yaw));
      yaw += 0.3 * n01(rng);
      const double step_m = o.step_min_m + (o.step_max_m - o.step_min_m) * unit(rng);
      Eigen::Vector2d next = p + step_m * Eigen::Vector2d(std::cos(yaw), std::sin(yaw));
      if (next.x() < x0 || next.x() > x0 + W || next.y() < 0.0 || next.y() > W) {
        // Turned back towards the centre of its area at the border.
        const Eigen::Vector2d to_centre = centre - p;
        yaw = std::atan2(to_centre.y(), to_centre.x()) + 0.4 * n01(rng);
        next = p + step_m * Eigen::Vector2d(std::cos(yaw), std::sin(yaw));
      }
      p = next;
    }
    std::vector<Eigen::Isometry3d>& odo = g.odometry.emplace_back();
    std::vector<Matrix6d>& cov = g.odometry_covariance.emplace_back();
    for (int i = 0; i + 1 < o.submaps_per_robot; ++i) {
      const Eigen::Isometry3d T_true =
          truth[static_cast<size_t>(i)].inverse() * truth[static_cast<size_t>(i + 1)];
      const double sigma_p_m = o.odometry_sigma_fraction * T_true.translation().norm();
      Vector6d sigma;
      sigma << sigma_p_m, sigma_p_m, sigma_p_m, o.odometry_roll_pitch_sigma_rad,
          o.odometry_roll_pitch_sigma_rad, o.odometry_yaw_sigma_rad;
      odo.push_back(synthetic_team_detail::Noisy(T_true, sigma, rng));
      cov.push_back(Matrix6d(sigma.cwiseAbs2().asDiagonal()));
    }
  }
  const int intra_per_robot =
      static_cast<int>(std::lround(o.intra_loop_fraction * o.submaps_per_robot));
  for (int r = 0; r < o.robots; ++r) {
    synthetic_team_detail::FindMatches(o, g, r, r, intra_per_robot, rng, &g.intra, nullptr);
  }
  std::vector<int> met(static_cast<size_t>(o.robots), 0);
  for (int a = 0; a < o.robots; ++a) {
    for (int b = a + 1; b < o.robots; ++b) {
      const size_t before = g.inter.size();
      synthetic_team_detail::FindMatches(o, g, a, b, o.inter_closures_per_pair, rng, &g.inter,
                                         &g.spare_inter);
      const int found = static_cast<int>(g.inter.size() - before);
      met[static_cast<size_t>(a)] += found;
      met[static_cast<size_t>(b)] += found;
    }
  }
  for (int r = 0; r < o.robots && o.robots > 1; ++r) {
    if (met[static_cast<size_t>(r)] == 0) {
      throw GraphError("synthetic team graph: robot " + std::to_string(r) +
                       " meets no other robot (seed " + std::to_string(seed) + ")");
    }
  }
  return g;
}

}  // namespace rover::mapping

#endif  // ROVER_BENCH_GRAPH_SYNTHETIC_TEAM_GRAPH_H_
