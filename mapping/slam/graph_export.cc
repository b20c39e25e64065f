#include "mapping/slam/graph_export.h"

namespace rover::mapping {
namespace {

// The 6x6 covariance RoverGraph uses for a factor: a frame switch's 4x4 in
// rows/columns (0, 1, 2, 5) plus the stiff roll/pitch prior.
Matrix6d GraphCovariance(const GraphFactorRecord& f, const RoverGraphOptions& options) {
  if (f.kind != FactorKind::kFrameSwitch) return f.covariance;
  Matrix6d C = f.covariance;
  const double s2 =
      options.frame_switch_roll_pitch_sigma_rad * options.frame_switch_roll_pitch_sigma_rad;
  C(3, 3) = s2;
  C(4, 4) = s2;
  return C;
}

}  // namespace

ExportedGraph ExportToG2o(const RoverGraph& solved, const std::vector<GraphFactorRecord>& factors,
                          const RoverGraphOptions& options) {
  ExportedGraph out;
  std::map<GraphKey, int64_t> id_of;
  const auto add_vertex = [&](const GraphKey& key) {
    if (id_of.count(key) != 0) return true;
    Eigen::Isometry3d T;
    try {
      T = solved.Estimate(key);
    } catch (const GraphError&) {
      return false;  // unanchored
    }
    const auto id = static_cast<int64_t>(id_of.size());
    id_of[key] = id;
    out.key_of_id[id] = key;
    out.graph.vertices.push_back({id, T});
    return true;
  };
  for (const GraphFactorRecord& f : factors) {
    if (f.kind == FactorKind::kPrior) add_vertex(f.a);  // anchors first
  }
  for (const GraphFactorRecord& f : factors) {
    if (!f.b || !add_vertex(f.a) || !add_vertex(*f.b)) {
      ++out.skipped;
      continue;
    }
    PoseEdge e;
    e.from = id_of.at(f.a);
    e.to = id_of.at(*f.b);
    e.measurement = f.T_a_b;
    e.information = InformationFromCovariance(f.T_a_b, GraphCovariance(f, options));
    out.graph.edges.push_back(e);
  }
  out.graph.dimension = 3;
  out.graph.source = "rover graph";
  return out;
}

}  // namespace rover::mapping
