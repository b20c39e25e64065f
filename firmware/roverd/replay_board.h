#ifndef ROVER_FIRMWARE_ROVERD_REPLAY_BOARD_H_
#define ROVER_FIRMWARE_ROVERD_REPLAY_BOARD_H_

// Board profile `replay`: a recorded EuRoC-layout dataset (a public one, or
// one from `rover-sim generate`) as roverd's sensors, through the same
// driver interfaces the hardware implements (drivers/replay). The IMU and
// the stereo pair are replayed, at the recorded pace or in lockstep; the
// filter and the VO are configured from the dataset's calibration
// (sensor.yaml files) and the board's optional estimator / VO files.
//
// Not replayed yet: the wheel drives' CAN frames of simulator datasets
// (mav0/can0); a CAN replay driver belongs in drivers/replay.

#include <memory>

#include "drivers/replay/euroc_dataset.h"
#include "drivers/replay/euroc_replay.h"
#include "firmware/roverd/roverd.h"
#include "firmware/runtime/board/board_config.h"

namespace rover::roverd {

class ReplayBoard {
 public:
  /// Loads the dataset and the configuration files. Throws naming the file
  /// and the problem (drivers::DatasetError, ConfigError, invalid_argument).
  explicit ReplayBoard(const runtime::BoardReplayOptions& options);

  /// The replay drivers (no trigger line, no CAN bus).
  RoverdDrivers drivers() { return {&imu_, &camera_, nullptr, nullptr}; }
  /// Estimator and camera set-up for this dataset; lockstep as configured.
  const RoverdOptions& options() const { return options_; }
  const drivers::EurocDataset& dataset() const { return dataset_; }

 private:
  drivers::EurocDataset dataset_;
  drivers::ReplayClock clock_;
  drivers::EurocImuReplay imu_;
  drivers::EurocStereoReplay camera_;
  RoverdOptions options_;
};

}  // namespace rover::roverd

#endif  // ROVER_FIRMWARE_ROVERD_REPLAY_BOARD_H_
