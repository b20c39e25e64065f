#ifndef ROVER_HIL_SIM_RENDER_APRILTAG_PATTERN_H_
#define ROVER_HIL_SIM_RENDER_APRILTAG_PATTERN_H_

// The printed cell pattern of an AprilTag 36h11 marker, taken from the
// apriltag library's own family definition so that what is rendered is what
// its detector decodes.

#include <cstdint>
#include <vector>

namespace rover::sim {

/// A square grid of cells, row-major, row 0 at the top of the printed tag
/// (tag frame -y), column 0 at its left (tag frame -x). 0 = black, 255 = white.
struct TagPattern {
  int cells_per_side = 0;  ///< total_width: includes the outer white ring (10 for 36h11)
  int border_cells = 0;    ///< width_at_border: cells across the black border square (8)
  std::vector<uint8_t> cells;
};

/// Pattern of tag36h11 id `id` (0 .. 586). Throws std::out_of_range otherwise.
TagPattern Tag36h11Pattern(int id);

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_RENDER_APRILTAG_PATTERN_H_
