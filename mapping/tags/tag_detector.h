#ifndef ROVER_MAPPING_TAGS_TAG_DETECTOR_H_
#define ROVER_MAPPING_TAGS_TAG_DETECTOR_H_

// AprilTag detection on rectified 8-bit images (Debian's libapriltag, the
// families a user configures). Besides what the library decodes, a detection
// must pass the checks the graph relies on: few corrected bits, a clear
// decision margin, all four corners inside the image (a tag cut by the image
// border has at least one corner guessed), and a convex quad of some area (a
// degenerate homography gives no pose), and sides that follow the tag's
// border in the image (tag_border_fit.h). What fails is returned as a refusal
// that says why, so mapd can count it and carry on.
//
// Corners follow OpenCV's pixel convention (the centre of the top-left pixel
// is (0, 0); the library puts it at (0.5, 0.5)), in the library's order:
// counter-clockwise in the image, corner 0 at the tag frame's (-s/2, +s/2),
// which is also the order OpenCV's SOLVEPNP_IPPE_SQUARE expects. Tag frame:
// origin at the centre, x right, y down, z into the tag.

#include <Eigen/Core>
#include <array>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace rover::mapping {

struct TagDetectorOptions {
  /// Library family names: tag36h11 (default), tag36h10, tag25h9, tag16h5,
  /// tagCircle21h7, tagCircle49h12, tagCustom48h12, tagStandard41h12,
  /// tagStandard52h13.
  std::vector<std::string> families{"tag36h11"};
  /// Bit errors the decoder may correct (apriltag_detector_add_family_bits).
  int max_bits_corrected = 2;
  /// Detections that needed more corrected bits than this are refused: a
  /// corrected tag is more often a misread one.
  int max_hamming = 0;
  /// Weaker decodes than this (the library's decision margin, grey levels)
  /// are refused.
  double min_decision_margin = 30.0;
  /// Quads are found on the image decimated by this, their edges then
  /// refined at full resolution (refine_edges). 2 takes a quarter of the
  /// time of 1 (bench_tag_model: 8 against 32 ms per 752x480 image) at the
  /// same corner accuracy, and loses only distant tags, which the error
  /// model mostly refuses as ambiguous anyway.
  double quad_decimate = 2.0;
  /// Gaussian blur [px] before quad detection; 0: none.
  double quad_sigma_px = 0.0;
  bool refine_edges = true;
  double decode_sharpening = 0.25;
  /// Corners closer than this to the image border [px] make the tag "cut by
  /// the image border".
  double border_margin_px = 2.0;
  /// Smallest quad area [px^2]: below it the pose is not worth a factor.
  double min_area_px2 = 100.0;
  /// A tag whose quad has a corner further than this from the border seen
  /// in the image (FitTagBorder) is refused: the library's segmentation ran
  /// past a thin or dim margin, and the pose from that corner may be the
  /// wrong solution of the ambiguity with nothing in the fit to show it.
  /// 0 turns the check off.
  double max_border_offset_px = 0.75;
  /// Library worker threads (mapd: 1, one low-priority thread).
  int threads = 1;

  /// Throws std::invalid_argument "TagDetectorOptions.<key>: expected ...,
  /// found ...".
  void Validate() const;
};

/// One decoded tag that passed the checks.
struct TagDetection {
  std::string family;
  int id = 0;
  int hamming = 0;               ///< bits corrected
  double decision_margin = 0.0;  ///< the library's
  std::array<Eigen::Vector2d, 4> corners_px{Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(),
                                            Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
  Eigen::Vector2d centre_px = Eigen::Vector2d::Zero();
};

/// A decoded tag that did not pass, and why.
struct TagRefusal {
  std::string family;
  int id = 0;
  std::string reason;
  /// Where the library found it (logged with the refusal).
  std::array<Eigen::Vector2d, 4> corners_px{Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(),
                                            Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
};

class TagDetector {
 public:
  /// Throws std::invalid_argument for invalid options (naming an unknown
  /// family and the known ones).
  explicit TagDetector(const TagDetectorOptions& options);
  ~TagDetector();
  TagDetector(const TagDetector&) = delete;
  TagDetector& operator=(const TagDetector&) = delete;

  /// Detects tags in an 8-bit single-channel image. Decoded tags that fail a
  /// check go to `refused` (if given) instead. Throws std::invalid_argument
  /// for another image type or an empty image.
  std::vector<TagDetection> Detect(const cv::Mat& mono8,
                                   std::vector<TagRefusal>* refused = nullptr);

  const TagDetectorOptions& options() const { return options_; }

 private:
  class Impl;
  TagDetectorOptions options_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_TAGS_TAG_DETECTOR_H_
