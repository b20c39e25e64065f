#include "mapping/graph/outlier_injection.h"

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "core/geometry/so3.h"
#include "mapping/graph/pose_graph_solver.h"

namespace rover::mapping {

int InjectFalseLoopClosures(PoseGraph& graph, double fraction, uint32_t seed) {
  std::mt19937 rng(seed);
  const int count =
      static_cast<int>(std::lround(fraction * static_cast<double>(graph.edges.size())));
  std::vector<size_t> templates;
  for (size_t k = 0; k < graph.edges.size(); ++k) {
    if (IsLoopClosure(graph.edges[k])) templates.push_back(k);
  }
  if (templates.empty()) {
    for (size_t k = 0; k < graph.edges.size(); ++k) templates.push_back(k);
  }
  const double extent = 10.0;
  std::uniform_int_distribution<size_t> vertex(0, graph.vertices.size() - 1);
  std::uniform_int_distribution<size_t> pick(0, templates.size() - 1);
  std::uniform_real_distribution<double> box(-extent, extent);
  std::uniform_real_distribution<double> angle(-std::numbers::pi, std::numbers::pi);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int n = 0; n < count; ++n) {
    PoseEdge e;
    do {
      e.from = graph.vertices[vertex(rng)].id;
      e.to = graph.vertices[vertex(rng)].id;
    } while (std::llabs(e.to - e.from) <= 1);
    e.information = graph.edges[templates[pick(rng)]].information;
    if (graph.dimension == 2) {
      e.measurement = PoseFromPlanar(box(rng), box(rng), angle(rng));
    } else {
      const Eigen::Vector3d axis =
          Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
      e.measurement.linear() = ExpSO3(angle(rng) * axis);
      e.measurement.translation() = Eigen::Vector3d(box(rng), box(rng), box(rng));
    }
    graph.edges.push_back(e);
  }
  return count;
}

}  // namespace rover::mapping
