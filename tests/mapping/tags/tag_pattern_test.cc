#include "mapping/tags/tag_pattern.h"

#include <apriltag/apriltag.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <stdexcept>

#include "mapping/tags/tag_family.h"

namespace rover::mapping {
namespace {

TEST(TagPatternTest, MatchesTheLibrarysTagImage) {
  for (const char* name : {"tag36h11", "tag25h9", "tag16h5"}) {
    const TagFamilyPtr family = CreateTagFamily(name);
    for (const int id : {0, 1, 5, static_cast<int>(family->ncodes) - 1}) {
      const TagPattern pattern = MakeTagPattern(name, id);
      image_u8_t* reference = apriltag_to_image(family.get(), id);
      ASSERT_EQ(pattern.cells_per_side, reference->width);
      ASSERT_EQ(pattern.cells_per_side, reference->height);
      EXPECT_EQ(pattern.border_cells, static_cast<int>(family->width_at_border));
      for (int y = 0; y < reference->height; ++y) {
        for (int x = 0; x < reference->width; ++x) {
          EXPECT_EQ(pattern.cells[static_cast<std::size_t>(y * pattern.cells_per_side + x)],
                    reference->buf[y * reference->stride + x])
              << name << " id " << id << " cell (" << x << ", " << y << ")";
        }
      }
      // image_u8_destroy is not exported by Debian's build: free as it would.
      std::free(reference->buf);
      std::free(reference);
    }
  }
}

TEST(TagPatternTest, RefusesWhatItCannotDraw) {
  EXPECT_THROW(MakeTagPattern("tag36h11", 587), std::out_of_range);
  EXPECT_THROW(MakeTagPattern("tag36h11", -1), std::out_of_range);
  EXPECT_THROW(MakeTagPattern("tag99h1", 0), std::invalid_argument);
  try {
    MakeTagPattern("tagStandard41h12", 0);
    FAIL() << "a reversed-border family was drawn";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("tagStandard41h12"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rover::mapping
