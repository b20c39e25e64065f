#ifndef ROVER_FIRMWARE_MAPD_POSE_HISTORY_H_
#define ROVER_FIRMWARE_MAPD_POSE_HISTORY_H_

// The recent filter estimates, so that a stereo pair can be placed at its
// capture time: estimates come at the IMU rate, pairs at the camera rate,
// and on different topics in no fixed order, so a pair is looked up once the
// estimates around its stamp have arrived.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Geometry>

#include "core/time/time.h"

namespace rover::mapd {

/// An estimate: T_local_body in local frame `frame_id`, with the filter's
/// covariance of it (the graph's convention: [dp (local); dtheta (right)]).
struct StampedPose {
  Time stamp;
  uint32_t frame_id = 0;
  Eigen::Isometry3d T_local_body = Eigen::Isometry3d::Identity();
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
};

class PoseHistory {
 public:
  /// Keeps the newest `capacity` estimates (> 0).
  explicit PoseHistory(std::size_t capacity);

  /// Appends an estimate; one older than the newest is ignored (returns
  /// false): estimates arrive in stamp order from the one filter.
  bool Add(const StampedPose& pose);

  /// The pose at `stamp`, interpolated between the two estimates around it
  /// (linear in position, slerp in rotation; the covariance is the larger
  /// one's, the later estimate's). Nullopt when `stamp` is older
  /// than the history, newer than its newest estimate, or falls across a
  /// frame switch (the two estimates are in different frames).
  std::optional<StampedPose> At(Time stamp) const;

  /// The newest estimate's stamp (nullopt when empty).
  std::optional<Time> newest() const;
  /// The oldest estimate's stamp (nullopt when empty).
  std::optional<Time> oldest() const;
  std::size_t size() const { return size_; }

 private:
  const StampedPose& Get(std::size_t i) const;  ///< 0 = oldest

  std::vector<StampedPose> ring_;
  std::size_t head_ = 0;  ///< next write
  std::size_t size_ = 0;
};

}  // namespace rover::mapd

#endif  // ROVER_FIRMWARE_MAPD_POSE_HISTORY_H_
