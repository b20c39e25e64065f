#ifndef ROVER_MAPPING_TAGS_TAG_PATTERN_H_
#define ROVER_MAPPING_TAGS_TAG_PATTERN_H_

// The printed cell pattern of an AprilTag, taken from the library's own
// family definition so that what is drawn is what its detector decodes: for
// the tag renderer here (the error model's look-up table) and the
// simulator's.

#include <cstdint>
#include <string>
#include <vector>

namespace rover::mapping {

/// A square grid of cells, row-major, row 0 at the top of the printed tag
/// (tag frame -y), column 0 at its left (tag frame -x). 0 = black, 255 =
/// white. The black border square, `border_cells` across, spans the tag's
/// size; the cells around it are the white margin.
struct TagPattern {
  int cells_per_side = 0;  ///< total_width: includes the outer white ring (10 for 36h11)
  int border_cells = 0;    ///< width_at_border: cells across the black border square (8)
  std::vector<uint8_t> cells;
};

/// The pattern of tag `id` of `family`. Throws std::invalid_argument for an
/// unknown family or one whose border is reversed (tagStandard*, tagCircle*,
/// tagCustom*: data outside the border, not drawn here), and
/// std::out_of_range for an id the family does not have.
TagPattern MakeTagPattern(const std::string& family, int id);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_TAGS_TAG_PATTERN_H_
