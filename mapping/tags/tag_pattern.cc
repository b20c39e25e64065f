#include "mapping/tags/tag_pattern.h"

#include <apriltag/apriltag.h>

#include <stdexcept>

#include "mapping/tags/tag_family.h"

namespace rover::mapping {

TagPattern MakeTagPattern(const std::string& family_name, int id) {
  const TagFamilyPtr family = CreateTagFamily(family_name);
  if (family->reversed_border) {
    throw std::invalid_argument("tag pattern: " + family_name +
                                " has its data outside the border; expected a classic family "
                                "(tag36h11, tag36h10, tag25h9, tag16h5)");
  }
  if (id < 0 || static_cast<uint32_t>(id) >= family->ncodes) {
    throw std::out_of_range("tag pattern: " + family_name + " has ids 0.." +
                            std::to_string(family->ncodes - 1) + ", found " + std::to_string(id));
  }
  TagPattern pattern;
  pattern.cells_per_side = family->total_width;
  pattern.border_cells = family->width_at_border;
  const int n = pattern.cells_per_side;
  // Everything outside the black border square is white (the printed
  // margin); the border square itself and every cleared data bit are black.
  pattern.cells.assign(static_cast<std::size_t>(n * n), 255);
  const int border_start = (n - pattern.border_cells) / 2;
  for (int y = border_start; y < border_start + pattern.border_cells; ++y) {
    for (int x = border_start; x < border_start + pattern.border_cells; ++x) {
      pattern.cells[static_cast<std::size_t>(y * n + x)] = 0;
    }
  }
  // Bit i (most significant first) sits at (bit_x[i], bit_y[i]) measured
  // from the outer corner of the black border.
  const uint64_t code = family->codes[id];
  for (uint32_t i = 0; i < family->nbits; ++i) {
    if ((code >> (family->nbits - 1 - i)) & 1u) {
      const int x = border_start + static_cast<int>(family->bit_x[i]);
      const int y = border_start + static_cast<int>(family->bit_y[i]);
      pattern.cells[static_cast<std::size_t>(y * n + x)] = 255;
    }
  }
  return pattern;
}

}  // namespace rover::mapping
