#ifndef ROVER_MAPPING_GRAPH_POSE_GRAPH_H_
#define ROVER_MAPPING_GRAPH_POSE_GRAPH_H_

// In-memory pose graph as read from / written to g2o files: vertices (poses)
// and relative-pose edges with information matrices. 2D graphs (SE(2)) are
// stored embedded in SE(3): z = 0, rotation about z only.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace rover::mapping {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// Any problem with a pose graph or its input: malformed file, missing vertex,
/// information matrix not positive definite, gauge freedom, NaN. what() names
/// the file and line ("graph.g2o:12: ...") or the offending variables.
class GraphError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A pose T_world_vertex.
struct PoseVertex {
  int64_t id = 0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
};

/// A relative-pose measurement T_from_to ("T_i_j") with its information matrix.
///
/// 3D: `information` is the 6x6 information of the g2o EDGE_SE3:QUAT error
/// e = [t(D); vec(q(D))] with D = measurement^-1 * T_i^-1 * T_j (translation
/// first; vec(q) the imaginary part of the unit quaternion with w >= 0).
/// 2D: the 3x3 information over (x, y, theta) of EDGE_SE2 is stored in rows
/// and columns (0, 1, 5); the other entries are zero.
struct PoseEdge {
  int64_t from = 0;
  int64_t to = 0;
  Eigen::Isometry3d measurement = Eigen::Isometry3d::Identity();
  Matrix6d information = Matrix6d::Identity();
  int line = 0;  ///< 1-based source line, 0 if not read from a file.
};

/// A pose graph. Vertex ids are unique; `vertices` keeps file order.
struct PoseGraph {
  int dimension = 3;  ///< 2 (SE(2)) or 3 (SE(3)).
  std::vector<PoseVertex> vertices;
  std::vector<PoseEdge> edges;
  std::string source;  ///< File name for messages.
  /// True if the file had no VERTEX lines: vertices were created from the
  /// edges with identity poses (and need an initialisation).
  bool vertices_implied = false;
};

/// The 3x3 (x, y, theta) block of a 2D edge's embedded information.
inline Eigen::Matrix3d PlanarInformation(const Matrix6d& information) {
  Eigen::Matrix3d I;
  const int idx[3] = {0, 1, 5};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) I(r, c) = information(idx[r], idx[c]);
  }
  return I;
}

/// Planar pose (x, y, theta) of an SE(3) pose embedded from SE(2).
inline Eigen::Vector3d PlanarPose(const Eigen::Isometry3d& T) {
  return {T.translation().x(), T.translation().y(), std::atan2(T.linear()(1, 0), T.linear()(0, 0))};
}

/// SE(3) embedding of the planar pose (x, y, theta).
inline Eigen::Isometry3d PoseFromPlanar(double x, double y, double theta) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, 0.0);
  return T;
}

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_GRAPH_POSE_GRAPH_H_
