#ifndef ROVER_MAPPING_LOOP_GRAVITY_DESCRIPTOR_H_
#define ROVER_MAPPING_LOOP_GRAVITY_DESCRIPTOR_H_

// Keypoint descriptors for gravity-aligned submaps (the thesis uses PCL's
// CSHOT, section 6.1.2; PCL is not available here). Both submaps of a match
// have roll = pitch = 0, so a descriptor needs invariance to yaw only, and
// "up" is known exactly: SHOT's hardest step, the local reference frame,
// reduces to one horizontal direction.
//
// The support (points within radius_m of the keypoint) is split into cells:
// azimuth sectors about the vertical axis through the keypoint x radial
// shells (3D distance) x elevation layers (below / above the keypoint). Each
// cell holds a histogram of its points' |n_z| (the cosine between normal and
// gravity, SHOT's feature with the LRF's z axis being gravity), with linear
// interpolation between neighbouring sectors, shells, layers and histogram
// bins, as SHOT does, so that noise moves mass gradually. Two ways to make
// it yaw-invariant:
//   kFourier  (default) the sectors are summarised per ring by the
//             magnitudes of their discrete Fourier transform over azimuth.
//             A yaw rotation shifts the sectors circularly, which changes
//             only the phases: invariant by construction, no reference
//             direction needed.
//   kOriented the sectors are counted from the keypoint's yaw reference
//             (below), SHOT-style. Keeps the relative azimuth between rings,
//             but breaks whenever the reference flips.
// The yaw reference itself is computed for every keypoint either way (the
// Hough voting needs it): the uphill direction of the support's weighted
// best-fit plane, -n_xy with n the plane normal pointing up. Gravity fixes
// its sign: uphill stays uphill from any viewpoint (SHOT needs a majority
// vote for the sign of each axis).
// Descriptors are L2-normalised; compare them by L2 distance.

#include <vector>

#include <Eigen/Core>

#include "core/config/config.h"
#include "mapping/loop/point_kd_tree.h"

namespace rover::mapping {

enum class GravityDescriptorKind { kFourier, kOriented };

struct GravityDescriptorOptions {
  GravityDescriptorKind kind = GravityDescriptorKind::kFourier;
  /// Support radius. The thesis uses 0.2 m on 2-4x denser clouds; on the
  /// 5 cm cloud 0.2 m holds ~50 surface points, too few for stable
  /// histograms (bench/mapping/loop_match_bench and the tests measured
  /// correspondence precision for 0.3-0.6 m).
  double radius_m = 0.5;
  int azimuth_sectors = 8;
  int radial_shells = 2;
  int elevation_layers = 2;
  /// Bins of the |n_z| histogram in each cell.
  int normal_bins = 4;
  /// Keypoints with fewer support points get no descriptor.
  int min_support_points = 20;

  /// Throws std::invalid_argument "GravityDescriptorOptions.<key>: ...".
  void Validate() const;
  /// Keys: kind (fourier | oriented), radius_m, azimuth_sectors,
  /// radial_shells, elevation_layers, normal_bins, min_support_points.
  static GravityDescriptorOptions Load(const ConfigNode& node);

  /// Length of one descriptor.
  int Length() const;
};

/// Descriptors of a set of keypoints.
struct KeypointDescriptors {
  /// One L2-normalised row per keypoint (zero rows for invalid ones).
  Eigen::MatrixXf descriptors;
  /// Local yaw reference (uphill direction) in the submap frame, radians.
  std::vector<float> yaw_reference_rad;
  /// |n_xy| of the support's plane: how well the reference is defined
  /// (0 on flat ground, 1 on a vertical surface).
  std::vector<float> yaw_reference_strength;
  /// False where the support was too small.
  std::vector<bool> valid;
};

/// Descriptors at `keypoints` over the cloud indexed by `cloud` with
/// per-point `normals` (ComputeSurfaceNormals, same order). Throws
/// std::invalid_argument if the sizes differ or the options are invalid.
KeypointDescriptors ComputeGravityDescriptors(const PointKdTree& cloud,
                                              const std::vector<Eigen::Vector3f>& normals,
                                              const std::vector<Eigen::Vector3f>& keypoints,
                                              const GravityDescriptorOptions& options);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_LOOP_GRAVITY_DESCRIPTOR_H_
