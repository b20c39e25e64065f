#ifndef ROVER_HIL_SIM_SENSORS_GPIO_EDGE_MODEL_H_
#define ROVER_HIL_SIM_SENSORS_GPIO_EDGE_MODEL_H_

// GPIO edges as the board's edge-event interface reports them: the stereo
// camera trigger (a pulse train the board generates at the camera rate) and
// the IMU data-ready line (one pulse per IMU sample).

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/config/config.h"
#include "core/time/time.h"
#include "drivers/gpio/gpio_edge.h"

namespace rover::sim {

struct GpioEdgeOptions {
  double camera_rate_hz = 10.0;        ///< [10, 20]
  double camera_phase_s = 0.0;         ///< first trigger after start, [0, 1 / rate)
  double camera_pulse_width_s = 1e-3;  ///< trigger high time
  uint32_t camera_trigger_line = 17;
  uint32_t imu_data_ready_line = 27;
  double imu_data_ready_delay_s = 0.0;  ///< from the sample instant to the rising edge
  double imu_data_ready_pulse_width_s = 50e-6;

  /// Loads every key above (all required, same names) with range checks.
  static GpioEdgeOptions Load(const ConfigNode& node);
  /// Loads a whole file, rejecting unknown keys.
  static GpioEdgeOptions LoadFile(const std::string& path);
};

class GpioEdgeModel {
 public:
  GpioEdgeModel(const GpioEdgeOptions& options, Time start);

  /// Rising edge of camera trigger k: start + phase + k / rate.
  Time CameraTriggerTime(uint64_t k) const;
  /// Rising-edge times of the camera triggers in [begin, end).
  std::vector<Time> CameraTriggerTimes(Time begin, Time end) const;
  /// Rising and falling camera trigger edges stamped in [begin, end), in order.
  std::vector<drivers::GpioEdge> CameraTriggerEdges(Time begin, Time end) const;
  /// The data-ready pulse (rising, falling) of an IMU sample taken at `sample_stamp`.
  std::array<drivers::GpioEdge, 2> ImuDataReadyEdges(Time sample_stamp) const;

  /// Merges edge lists into one, ordered by time (stable for equal stamps).
  static void SortByTime(std::vector<drivers::GpioEdge>* edges);

  const GpioEdgeOptions& options() const { return options_; }

 private:
  GpioEdgeOptions options_;
  Time start_;
};

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_SENSORS_GPIO_EDGE_MODEL_H_
