#include "mapping/loop/surface_normals.h"

#include <Eigen/Eigenvalues>

namespace rover::mapping {

std::vector<Eigen::Vector3f> ComputeSurfaceNormals(const PointKdTree& tree, float radius_m,
                                                   std::vector<float>* planarity) {
  const std::vector<Eigen::Vector3f>& points = tree.points();
  std::vector<Eigen::Vector3f> normals(points.size(), Eigen::Vector3f::UnitZ());
  if (planarity) planarity->assign(points.size(), 0.0f);
  std::vector<Neighbour> neighbours;
  for (std::size_t i = 0; i < points.size(); ++i) {
    tree.Radius(points[i], radius_m, &neighbours);
    if (neighbours.size() < 3) continue;
    // Centred sums in double: the submap frame's coordinates reach tens of
    // metres, the neighbourhood a few centimetres.
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const Neighbour& n : neighbours) mean += points[n.index].cast<double>();
    mean /= static_cast<double>(neighbours.size());
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const Neighbour& n : neighbours) {
      const Eigen::Vector3d d = points[n.index].cast<double>() - mean;
      cov.noalias() += d * d.transpose();
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
    Eigen::Vector3d n = eig.eigenvectors().col(0);
    if (n.z() < 0.0) n = -n;
    normals[i] = n.cast<float>();
    if (planarity) {
      const double trace = eig.eigenvalues().sum();
      (*planarity)[i] =
          trace > 0.0 ? static_cast<float>(1.0 - 3.0 * eig.eigenvalues()(0) / trace) : 0.0f;
    }
  }
  return normals;
}

}  // namespace rover::mapping
