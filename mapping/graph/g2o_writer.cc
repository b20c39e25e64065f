#include "mapping/graph/g2o_writer.h"

#include <array>
#include <charconv>
#include <fstream>

namespace rover::mapping {
namespace {

// Shortest decimal text that parses back to exactly `value`.
void Put(std::ostream& out, double value) {
  std::array<char, 32> buffer{};
  const auto [ptr, ec] = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  out << ' ';
  out.write(buffer.data(), ptr - buffer.data());
}

void PutQuaternionPose(std::ostream& out, const Eigen::Isometry3d& T) {
  Eigen::Quaterniond q(T.linear());
  q.normalize();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  for (int i = 0; i < 3; ++i) Put(out, T.translation()(i));
  Put(out, q.x());
  Put(out, q.y());
  Put(out, q.z());
  Put(out, q.w());
}

}  // namespace

void WriteG2o(const PoseGraph& graph, std::ostream& out) {
  const bool planar = graph.dimension == 2;
  for (const PoseVertex& v : graph.vertices) {
    out << (planar ? "VERTEX_SE2 " : "VERTEX_SE3:QUAT ") << v.id;
    if (planar) {
      const Eigen::Vector3d p = PlanarPose(v.pose);
      for (int i = 0; i < 3; ++i) Put(out, p(i));
    } else {
      PutQuaternionPose(out, v.pose);
    }
    out << '\n';
  }
  for (const PoseEdge& e : graph.edges) {
    out << (planar ? "EDGE_SE2 " : "EDGE_SE3:QUAT ") << e.from << ' ' << e.to;
    if (planar) {
      const Eigen::Vector3d p = PlanarPose(e.measurement);
      for (int i = 0; i < 3; ++i) Put(out, p(i));
      const Eigen::Matrix3d I = PlanarInformation(e.information);
      for (int r = 0; r < 3; ++r) {
        for (int c = r; c < 3; ++c) Put(out, I(r, c));
      }
    } else {
      PutQuaternionPose(out, e.measurement);
      for (int r = 0; r < 6; ++r) {
        for (int c = r; c < 6; ++c) Put(out, e.information(r, c));
      }
    }
    out << '\n';
  }
}

void WriteG2oFile(const PoseGraph& graph, const std::string& path) {
  std::ofstream out(path);
  if (!out) throw GraphError(path + ": cannot open for writing");
  WriteG2o(graph, out);
  out.flush();
  if (!out) throw GraphError(path + ": write error");
}

}  // namespace rover::mapping
