#include "host/tags/lut_command.h"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <optional>
#include <stdexcept>

#include "core/calib/board_calibration.h"
#include "core/calib/stereo_rectifier.h"
#include "core/cli/progress_bar.h"
#include "core/cli/report_format.h"

namespace rover::host {

std::string TagErrorTablePath(const std::string& calibration, const std::string& family,
                              double tag_size_m) {
  return (std::filesystem::path(calibration).parent_path() /
          mapping::TagErrorTableFileName(family, tag_size_m))
      .string();
}

int RunLut(const LutCommandOptions& options, std::ostream& out, std::ostream& err) {
  mapping::TagErrorTableSpec spec = options.spec;
  try {
    const calib::BoardCalibration board = calib::BoardCalibration::LoadFile(options.calibration);
    if (!board.stereo) {
      err << "rover-tags lut: " << options.calibration
          << ": expected a `cameras` section (the stereo head the tags are seen with)\n";
      return 1;
    }
    const std::optional<calib::StereoRectifier> rectifier =
        calib::StereoRectifier::Create(board.stereo->cam0, board.stereo->cam1);
    if (!rectifier) {
      err << "rover-tags lut: " << options.calibration
          << ": the stereo head cannot be rectified (see rover-calib check)\n";
      return 1;
    }
    spec.camera = rectifier->intrinsics();
    spec.image_size = rectifier->image_size();
    spec.Validate();
  } catch (const std::exception& e) {
    err << "rover-tags lut: " << e.what() << "\n";
    return 1;
  }
  const std::string path =
      options.output.empty() ? TagErrorTablePath(options.calibration, spec.family, spec.tag_size_m)
                             : options.output;
  out << "rover-tags lut: " << spec.family << " " << spec.tag_size_m * 1000.0 << " mm tags, "
      << spec.image_size.width << "x" << spec.image_size.height << " rectified (fx "
      << cli::Fixed(spec.camera.fx, 1) << " px), corners +-" << spec.corner_delta_px << " px, "
      << spec.distance_steps << " distances in [" << spec.min_distance_m << ", "
      << spec.max_distance_m << "] m x " << spec.tilt_steps << " tilts in [-"
      << cli::Fixed(spec.max_tilt_rad * 180.0 / M_PI, 1) << ", "
      << cli::Fixed(spec.max_tilt_rad * 180.0 / M_PI, 1) << "] deg\n";
  const auto start = std::chrono::steady_clock::now();
  const auto total =
      static_cast<uint64_t>(spec.distance_steps) * static_cast<uint64_t>(spec.tilt_steps);
  cli::ProgressBar bar(err, "rover-tags lut", total, "cells", options.progress_tty);
  const mapping::TagErrorTable table =
      mapping::TagErrorTable::Build(spec, [&](std::size_t done, std::size_t) { bar.Update(done); });
  bar.Finish();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  try {
    table.Save(path);
  } catch (const std::exception& e) {
    err << "rover-tags lut: " << e.what() << "\n";
    return 2;
  }
  // What the table says at a few distances, head-on and at 60 degrees.
  cli::TextTable summary({"distance m", "tilt deg", "depth m", "lateral m", "rotation deg"});
  for (const double d : {1.0, 2.0, 4.0, 7.0}) {
    for (const double tilt_deg : {0.0, 60.0}) {
      const mapping::TagPoseErrors e = table.Lookup(d, tilt_deg * M_PI / 180.0);
      summary.AddRow({cli::Fixed(d, 1), cli::Fixed(tilt_deg, 0), cli::Fixed(e[2], 4),
                      cli::Fixed(std::max(e[0], e[1]), 4),
                      cli::Fixed(e.tail<3>().maxCoeff() * 180.0 / M_PI, 2)});
    }
  }
  out << "maximum errors (after post-processing):\n" << summary.ToString();
  out << "detected in " << table.detected_cells() << " of " << total << " cells; the rest "
      << "filled as the thesis does; wrote " << path << "\n";
  out << cli::ResultLine({{"cells", std::to_string(total)},
                          {"detected_cells", std::to_string(table.detected_cells())},
                          {"time_s", cli::Fixed(seconds, 1)},
                          {"path", path}})
      << "\n";
  return 0;
}

}  // namespace rover::host
