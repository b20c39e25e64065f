#ifndef ROVER_MAPPING_TAGS_TAG_OBSERVER_H_
#define ROVER_MAPPING_TAGS_TAG_OBSERVER_H_

// One camera's tag detections as the graph needs them: detect on a rectified
// image, keep the configured markers (the size of each id, and whether it
// sits on a fixed landmark or on another robot), solve both poses, judge
// the uncertainty with the error model, and say for every decoded tag
// whether it is accepted and, if not, why. Counts by outcome for mapd's
// status. Not thread-safe: one observer per thread.

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

#include "core/calib/stereo_rectifier.h"
#include "core/config/config.h"
#include "core/log/msgs/rover_msgs.h"
#include "mapping/tags/tag_detector.h"
#include "mapping/tags/tag_error_model.h"
#include "mapping/tags/tag_error_table.h"
#include "mapping/tags/tag_pose.h"

namespace rover::mapping {

/// One configured marker: a tag id of the family, its printed size and what
/// carries it.
struct TagMarker {
  int id = 0;
  double size_m = 0.0;
  /// A fixed landmark (an `o` factor to landmark `landmark`) or a robot (a
  /// `d` factor to robot `robot`).
  enum class Carrier { kLandmark, kRobot };
  Carrier carrier = Carrier::kLandmark;
  int64_t landmark = 0;
  int robot = 0;
  /// Where the tag sits on its carrier (tag frame: x right, y down, z into
  /// the tag).
  Eigen::Isometry3d T_carrier_tag = Eigen::Isometry3d::Identity();
};

struct TagObserverOptions {
  TagDetectorOptions detector{};
  TagErrorModelOptions model{};
  std::vector<TagMarker> markers;

  /// Throws std::invalid_argument naming the key: the detector's and the
  /// model's checks, marker ids unique and within the family, sizes > 0,
  /// one family (the detector's first).
  void Validate() const;
  /// Keys: families, max_hamming, min_decision_margin, quad_decimate,
  /// corner_delta_px, sigma_per_max_error, corner_sigma_px,
  /// tilt_sigma_exponent, frontal_sigma_gain, frontal_tilt_deg, aligned_edge_sigma_px,
  /// small_tag_side_px, flip_sigma_factor, max_tilt_deg,
  /// max_reprojection_rmse_px, max_flipped_fraction, max_ambiguity_ratio,
  /// model (table | analytic), markers: [{id, size_m,
  /// landmark: N | robot: N, T_carrier_tag: 4x4 row-major (optional)}].
  static TagObserverOptions Load(const ConfigNode& node);
};

struct TagObservation {
  TagDetection detection;
  /// Null for an id not in the configuration and for a tag the detector
  /// refused (its id may be misread).
  const TagMarker* marker = nullptr;
  bool not_configured = false;  ///< decoded cleanly, but the id is not in the configuration
  std::optional<TagPose> pose;
  TagUncertainty uncertainty;
  bool accepted = false;
  std::string refusal;  ///< why not, when not accepted
  /// Ambiguous detections only (uncertainty.ambiguous): the covariance of
  /// each solution (best, alternative), should the tag's other sightings
  /// decide between them, and of the best inflated to cover both
  /// (TagErrorModel::Inflated), should nothing decide.
  std::array<TagUncertainty, 2> solutions{};
  TagUncertainty inflated;
};

struct TagObserverStats {
  uint64_t images = 0;
  uint64_t decoded = 0;  ///< tags the library decoded
  uint64_t accepted = 0;
  uint64_t not_configured = 0;
  uint64_t refused_by_detector = 0;  ///< misread, weak, cut by the border, degenerate
  uint64_t refused_by_model = 0;     ///< ambiguous (flips, equal fits) or degenerate
  uint64_t no_pose = 0;
};

/// The log record of one observation (header.stamp `stamp_ns`, frame_id
/// `camera_frame`, e.g. "cam0"), so that detections can be replayed.
log::rover_msgs::TagDetection ToMsg(const TagObservation& observation, int64_t stamp_ns,
                                    std::string_view camera_frame);

/// The error tables `options` needs (one per marker size; none for the
/// analytic model) for `camera` at `image_size`, read from `directory`
/// (TagErrorTableFileName). A table that is missing, unreadable or made for
/// another camera is built on `grid`'s distances and tilts (the default:
/// 60 x 60, a few seconds per table) and saved there when `build_missing` is
/// set; otherwise
/// std::runtime_error names the file, what is wrong and the rover-tags
/// command that makes it. `say` gets one line per table read or built.
std::vector<TagErrorTable> LoadTagErrorTables(
    const TagObserverOptions& options, const calib::RectifiedIntrinsics& camera,
    cv::Size image_size, const std::string& directory, bool build_missing,
    const std::function<void(const std::string&)>& say = {}, const TagErrorTableSpec& grid = {});

class TagObserver {
 public:
  /// The table model needs, for every configured marker size, a table made
  /// for `camera`, `image_size`, the family and that size (rover-tags lut).
  /// Throws std::invalid_argument saying what does not fit or is missing.
  TagObserver(const TagObserverOptions& options, const calib::RectifiedIntrinsics& camera,
              cv::Size image_size, const std::vector<TagErrorTable>& tables);

  /// Every decoded tag in one rectified image, accepted or with its refusal.
  /// Throws std::invalid_argument for an image of another size or type.
  std::vector<TagObservation> Observe(const cv::Mat& rectified);

  const TagObserverStats& stats() const { return stats_; }

 private:
  TagObserverOptions options_;
  calib::RectifiedIntrinsics camera_;
  cv::Size image_size_;
  TagDetector detector_;
  /// One model per marker size [0.1 mm], each with its table.
  std::map<int64_t, TagErrorModel> models_;
  TagObserverStats stats_;
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_TAGS_TAG_OBSERVER_H_
