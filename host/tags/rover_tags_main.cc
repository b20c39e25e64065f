// rover-tags: AprilTag tools for the rover's detections (mapping/tags).

#include <unistd.h>

#include <CLI/CLI.hpp>

#include <cmath>
#include <iostream>

#include "host/tags/lut_command.h"

int main(int argc, char** argv) {
  CLI::App app{
      "rover-tags: AprilTag tools for the rover's tag detections. `lut` builds the detection\n"
      "error table of the thesis's model (maximum pose errors over distance and tilt, from tags\n"
      "rendered at each grid pose, detected, their corners perturbed by +-delta px in all 256\n"
      "combinations) for a board's rectified camera, a family and a tag size, and writes it\n"
      "next to the board's calibration. mapd reads it from the board profile's mapd.tag_tables\n"
      "folder (copy it there, or point tag_tables at the calibration's folder) for every marker\n"
      "size of its marker file."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "rover-tags 0.1.0");

  rover::host::LutCommandOptions lut;
  double max_tilt_deg = 89.0;
  auto* cmd = app.add_subcommand("lut", "Build the detection error table for one camera and tag");
  cmd->add_option("--calibration", lut.calibration, "the board's calibration (rover-calibration-1)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--family", lut.spec.family, "tag family (tag36h11, tag36h10, tag25h9, tag16h5)")
      ->capture_default_str();
  cmd->add_option("--tag-size-m", lut.spec.tag_size_m,
                  "side of the tag's black square [m], as printed")
      ->required()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--corner-delta-px", lut.spec.corner_delta_px,
                  "the calibration's pixel error: corners perturbed by +- this [px]")
      ->capture_default_str();
  cmd->add_option("--min-distance-m", lut.spec.min_distance_m, "nearest grid distance [m]")
      ->capture_default_str();
  cmd->add_option("--max-distance-m", lut.spec.max_distance_m, "farthest grid distance [m]")
      ->capture_default_str();
  cmd->add_option("--distance-steps", lut.spec.distance_steps,
                  "grid distances (the thesis: 200; about 5 ms per cell)")
      ->capture_default_str();
  cmd->add_option("--max-tilt-deg", max_tilt_deg, "grid tilts in [-max, max] [deg]")
      ->capture_default_str();
  cmd->add_option("--tilt-steps", lut.spec.tilt_steps, "grid tilts (the thesis: 200)")
      ->capture_default_str();
  cmd->add_option("--blur-px", lut.spec.render.blur_sigma_px,
                  "Gaussian blur of the rendered tags [px], for the lens's defocus")
      ->capture_default_str();
  cmd->add_option("-o,--out", lut.output,
                  "table to write (default: beside the calibration, "
                  "tag_errors_<family>_<size>mm.yaml)");
  CLI11_PARSE(app, argc, argv);
  lut.spec.max_tilt_rad = max_tilt_deg * M_PI / 180.0;
  lut.progress_tty = ::isatty(STDERR_FILENO) != 0;
  return rover::host::RunLut(lut, std::cout, std::cerr);
}
