#ifndef ROVER_HIL_SIM_DATASET_DATASET_GENERATOR_H_
#define ROVER_HIL_SIM_DATASET_DATASET_GENERATOR_H_

// Turns a scenario into an EuRoC-layout dataset: generates the world, drives
// the route, samples every sensor model, renders the stereo pairs and writes
// it all, with the world's ground truth in DIR/world/. Deterministic: the
// same scenario, seed and binary give byte-identical files.

#include <cstdint>
#include <functional>
#include <string>

#include "hil/sim/scenario/scenario.h"

namespace rover::sim {

struct GenerateOptions {
  uint64_t seed = 1;
  std::string out_dir;
  /// Stop after this much simulated time (0: the whole route).
  double max_duration_s = 0.0;
  /// Called about once per rendered frame with progress in [0, 1].
  std::function<void(double fraction, double sim_time_s)> progress;
};

struct GenerateResult {
  double sim_duration_s = 0.0;
  double distance_m = 0.0;
  uint64_t imu_samples = 0;
  uint64_t stereo_frames = 0;
  uint64_t can_frames = 0;
  uint64_t gpio_edges = 0;
  double wall_time_s = 0.0;
  double world_time_s = 0.0;   ///< world generation + ground-truth export
  double render_time_s = 0.0;  ///< rendering the stereo pairs
  double write_time_s = 0.0;   ///< encoding and writing images
  std::string gl_renderer;
  /// Datasets written: 1, plus one per other rover (in <out>/<rover name>/).
  std::size_t rover_datasets = 0;
};

/// Generates the dataset into options.out_dir (which must not hold a mav0/).
/// With other rovers in the scenario, every rover carries tags and each
/// other rover's own recording goes to <out_dir>/<rover name>/ (rover_b, ...),
/// so both sides of a mutual sighting are in the data. Counts in the result
/// are summed over all rovers; distance is the main rover's.
/// Throws on bad options or I/O errors, with a message naming what failed.
GenerateResult GenerateDataset(const Scenario& scenario, const GenerateOptions& options);

/// The time stamp of the dataset's first sample. Datasets use a fixed
/// CLOCK_MONOTONIC-like origin, so replaying one never collides with t = 0.
inline constexpr Time kDatasetStartTime = Time::FromNanoseconds(1'000'000'000'000);

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_DATASET_DATASET_GENERATOR_H_
