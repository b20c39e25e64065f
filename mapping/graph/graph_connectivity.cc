#include "mapping/graph/graph_connectivity.h"

#include <cmath>
#include <numeric>

#include "mapping/graph/se_sync_objective.h"

namespace rover::mapping {
namespace {

int Find(std::vector<int>& parent, int x) {
  while (parent[static_cast<size_t>(x)] != x) {
    parent[static_cast<size_t>(x)] = parent[static_cast<size_t>(parent[static_cast<size_t>(x)])];
    x = parent[static_cast<size_t>(x)];
  }
  return x;
}

}  // namespace

std::vector<int> ConnectedComponents(const PoseGraph& graph) {
  const auto index = VertexIndex(graph);
  std::vector<int> parent(graph.vertices.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (const PoseEdge& e : graph.edges) {
    const int a = Find(parent, index.at(e.from));
    const int b = Find(parent, index.at(e.to));
    if (a != b) parent[static_cast<size_t>(std::max(a, b))] = std::min(a, b);
  }
  std::vector<int> label(graph.vertices.size(), -1);
  std::vector<int> root_label(graph.vertices.size(), -1);
  int next = 0;
  for (size_t k = 0; k < graph.vertices.size(); ++k) {
    const auto root = static_cast<size_t>(Find(parent, static_cast<int>(k)));
    if (root_label[root] < 0) root_label[root] = next++;
    label[k] = root_label[root];
  }
  return label;
}

std::string DescribeIds(const std::vector<int64_t>& ids) {
  std::string s = "ids ";
  const size_t shown = std::min<size_t>(ids.size(), 5);
  for (size_t k = 0; k < shown; ++k) {
    if (k > 0) s += ", ";
    s += std::to_string(ids[k]);
  }
  if (ids.size() > shown) s += ", ...";
  s += " (" + std::to_string(ids.size()) + (ids.size() == 1 ? " vertex)" : " vertices)");
  return s;
}

void CheckGaugeAndFinite(const PoseGraph& graph) {
  if (graph.vertices.empty()) throw GraphError(graph.source + ": graph has no vertices");
  for (const PoseVertex& v : graph.vertices) {
    if (!v.pose.matrix().allFinite()) {
      throw GraphError(graph.source + ": NaN input: vertex " + std::to_string(v.id) +
                       " has a non-finite pose");
    }
  }
  for (const PoseEdge& e : graph.edges) {
    if (!e.measurement.matrix().allFinite() || !e.information.allFinite()) {
      throw GraphError(graph.source + ":" + std::to_string(e.line) + ": NaN input: edge " +
                       std::to_string(e.from) + " -> " + std::to_string(e.to) +
                       " has a non-finite measurement or information");
    }
  }
  const std::vector<int> label = ConnectedComponents(graph);
  const int count = label.empty() ? 0 : *std::max_element(label.begin(), label.end()) + 1;
  if (count <= 1) return;
  std::string message = graph.source + ": gauge problem: the graph has " + std::to_string(count) +
                        " connected components but only vertex " +
                        std::to_string(graph.vertices.front().id) +
                        " is anchored; components without an anchor:";
  for (int c = 1; c < count; ++c) {
    std::vector<int64_t> ids;
    for (size_t k = 0; k < label.size(); ++k) {
      if (label[k] == c) ids.push_back(graph.vertices[k].id);
    }
    message += "\n  component " + std::to_string(c) + ": " + DescribeIds(ids);
  }
  throw GraphError(message);
}

}  // namespace rover::mapping
