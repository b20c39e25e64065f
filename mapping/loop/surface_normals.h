#ifndef ROVER_MAPPING_LOOP_SURFACE_NORMALS_H_
#define ROVER_MAPPING_LOOP_SURFACE_NORMALS_H_

// Surface normals of a submap's point cloud by principal component analysis
// of each point's neighbourhood: the eigenvector of the smallest eigenvalue
// of the neighbours' covariance. Submaps are gravity-aligned, so the sign is
// fixed by gravity rather than by a viewpoint (the cloud keeps none): every
// normal points up (n_z >= 0), and a vertical surface's normal keeps
// whichever horizontal sign PCA gave it (the descriptors use |n_z| only,
// point-to-plane ICP is sign-free).

#include <vector>

#include <Eigen/Core>

#include "mapping/loop/point_kd_tree.h"

namespace rover::mapping {

/// Normals of every point of `tree`: the PCA normal of the points within
/// `radius_m` (at least 3 needed, else (0, 0, 1) with zero confidence).
/// `planarity` (optional) receives 1 - 3 lambda_min / trace, in [0, 1]: 1 on
/// a clean plane, 0 for isotropic scatter.
std::vector<Eigen::Vector3f> ComputeSurfaceNormals(const PointKdTree& tree, float radius_m,
                                                   std::vector<float>* planarity = nullptr);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_LOOP_SURFACE_NORMALS_H_
