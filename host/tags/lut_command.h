#ifndef ROVER_HOST_TAGS_LUT_COMMAND_H_
#define ROVER_HOST_TAGS_LUT_COMMAND_H_

// `rover-tags lut`: builds the tag detection error table (mapping/tags) for
// a board's rectified stereo camera, a tag family and a tag size, and writes
// it next to the board's calibration.

#include <ostream>
#include <string>

#include "mapping/tags/tag_error_table.h"

namespace rover::host {

struct LutCommandOptions {
  std::string calibration;  ///< the board's calibration (rover-calibration-1)
  std::string output;       ///< empty: TagErrorTablePath(calibration, family, size)
  /// Camera, family, size and grid; the camera and image size are taken from
  /// the calibration's rectification.
  mapping::TagErrorTableSpec spec;
  bool progress_tty = false;  ///< draw the progress bar in place
};

/// The table's default path: beside `calibration`, named by
/// mapping::TagErrorTableFileName.
std::string TagErrorTablePath(const std::string& calibration, const std::string& family,
                              double tag_size_m);

/// Exit status: 0 written, 1 invalid input (the message names the file and
/// the problem), 2 the table could not be written. Ends with
///   RESULT cells=... detected_cells=... time_s=... path=...
int RunLut(const LutCommandOptions& options, std::ostream& out, std::ostream& err);

}  // namespace rover::host

#endif  // ROVER_HOST_TAGS_LUT_COMMAND_H_
