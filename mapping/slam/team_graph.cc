#include "mapping/slam/team_graph.h"

#include <algorithm>
#include <set>
#include <stdexcept>

#include "mapping/graph/rover_graph.h"
#include "mapping/slam/graph_factor_record.h"

namespace rover::mapping {

TeamGraphSolution SolveTeamGraph(const GraphLogContents& all) {
  TeamGraphSolution out;
  out.problems = all.problems;
  std::set<int> robots;
  for (const GraphFactorRecord& f : all.factors) {
    if (f.a.type != GraphKey::Type::kLandmark) robots.insert(f.a.robot);
    if (f.kind == FactorKind::kPrior) {
      out.anchor_robot = out.anchor_robot < 0 ? f.a.robot : std::min(out.anchor_robot, f.a.robot);
    }
  }
  if (out.anchor_robot < 0) {
    throw std::runtime_error("the mapd logs hold no prior: no rover's map can be anchored");
  }
  RoverGraph graph;
  for (const GraphFactorRecord& f : all.factors) {
    if (f.kind == FactorKind::kPrior && f.a.robot != out.anchor_robot) {
      ++out.priors_left_out;
      continue;
    }
    try {
      AddToGraph(f, &graph);
      ++out.factors;
    } catch (const std::exception& e) {
      out.problems.push_back(std::string("factor left out: ") + e.what());
    }
  }
  graph.Optimize();
  std::set<int> placed;
  for (const GraphKey& key : graph.Keys()) {
    if (key.type != GraphKey::Type::kOrigin) continue;
    try {
      out.origins[{key.robot, key.index}] = graph.Estimate(key);
      placed.insert(key.robot);
    } catch (const std::exception&) {
      // Not linked to the anchor: left out.
    }
  }
  out.robots.assign(robots.begin(), robots.end());
  for (const int r : robots) {
    if (placed.count(r) == 0) out.unplaced_robots.push_back(r);
  }
  return out;
}

}  // namespace rover::mapping
