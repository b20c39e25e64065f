#ifndef ROVER_MAPPING_TAGS_TAG_BORDER_FIT_H_
#define ROVER_MAPPING_TAGS_TAG_BORDER_FIT_H_

// Checks that each side of a detected quad lies on the tag's border in the
// image: the step between the border ring and the ring next to it outside.
//
// The library fits its quad to a thresholded segmentation. Where the white
// margin around the black square is thin and dim (a tag on a face in the
// shade, with bright ground or sky just beyond the carrier's edge), the
// local threshold counts the margin as dark, the segment runs on to the
// carrier's edge, and one corner lands a few pixels off along it. Such a tag
// still decodes, and its corners still fit a square well enough (0.3-0.5 px
// RMSE), yet the pose from them can be the wrong solution of the planar
// ambiguity with no sign of it in the fit. Looking at the image along each
// side finds it: the step sits where the side says at one end and pixels
// away at the other.
//
// Method: at points spread along each side, the intensity profile across it
// (bilinear, quarter-pixel steps, within three quarters of a bit on either
// side, a bit measured across the side, so that neither the data bits inside
// nor the margin's outer edge is reached); the step is the centroid of the
// gradient lobe of the border's polarity around its peak, where it stays
// above half the peak. A line through these offsets along the side,
// evaluated at the side's two ends, and the two sides that meet at a corner
// say how far that corner lies off the border.

#include <Eigen/Core>
#include <array>
#include <opencv2/core.hpp>

namespace rover::mapping {

/// The border ring's geometry as the family defines it.
struct TagBorderGeometry {
  /// Cells across the border square (the library's width_at_border: 8 for
  /// tag36h11); a side of the quad spans this many cells.
  int border_cells = 8;
  /// True for families whose border is light inside and dark outside (the
  /// library's reversed_border).
  bool reversed = false;
};

/// How well the quad's sides follow the border.
struct TagBorderFit {
  /// Per side k (corner k to corner k+1): how far the border lies off the
  /// side at each of its two ends, across the side, outward positive [px].
  std::array<std::array<double, 2>, 4> end_offsets_px{};
  /// Per side: profiles where no step of the border's polarity was found
  /// within the window (or the step was much weaker than the tag's median
  /// one), over all profiles taken.
  std::array<double, 4> missing_fraction{};
  /// Per corner: how far the border's corner lies from it [px], from the
  /// end offsets of the two sides that meet there; infinite where a side
  /// has fewer than two profiles with a step.
  std::array<double, 4> corner_offsets_px{};
  /// The largest corner offset, and its corner.
  double worst_offset_px = 0.0;
  int worst_corner = 0;
  /// False when the quad is too small to take profiles (a side shorter than
  /// 4 px) or a profile leaves the image; nothing above is then set.
  bool measured = false;
};

/// Measures the border fit of the quad `corners_px` (OpenCV pixel
/// convention, the detector's corner order) in the 8-bit single-channel
/// `image`. Allocates nothing.
TagBorderFit FitTagBorder(const cv::Mat& image, const std::array<Eigen::Vector2d, 4>& corners_px,
                          const TagBorderGeometry& geometry);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_TAGS_TAG_BORDER_FIT_H_
