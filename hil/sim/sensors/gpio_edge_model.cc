#include "hil/sim/sensors/gpio_edge_model.h"

#include <algorithm>
#include <cmath>

namespace rover::sim {

GpioEdgeOptions GpioEdgeOptions::Load(const ConfigNode& node) {
  GpioEdgeOptions o;
  o.camera_rate_hz = node.GetInRange<double>("camera_rate_hz", 10.0, 20.0);
  const double period_s = 1.0 / o.camera_rate_hz;
  o.camera_phase_s = node.GetInRange<double>("camera_phase_s", 0.0, period_s);
  if (o.camera_phase_s >= period_s) node.Fail("camera_phase_s", "must be below 1 / camera_rate_hz");
  o.camera_pulse_width_s = node.GetInRange<double>("camera_pulse_width_s", 1e-6, 0.5 * period_s);
  o.camera_trigger_line = node.GetInRange<uint32_t>("camera_trigger_line", 0, 1023);
  o.imu_data_ready_line = node.GetInRange<uint32_t>("imu_data_ready_line", 0, 1023);
  if (o.imu_data_ready_line == o.camera_trigger_line) {
    node.Fail("imu_data_ready_line", "must differ from camera_trigger_line");
  }
  // Bounded by the shortest IMU period (1 kHz) so pulses never overlap.
  o.imu_data_ready_delay_s = node.GetInRange<double>("imu_data_ready_delay_s", 0.0, 5e-4);
  o.imu_data_ready_pulse_width_s =
      node.GetInRange<double>("imu_data_ready_pulse_width_s", 1e-7, 5e-4);
  return o;
}

GpioEdgeOptions GpioEdgeOptions::LoadFile(const std::string& path) {
  const ConfigNode root = ConfigNode::LoadFile(path);
  GpioEdgeOptions o = Load(root);
  root.CheckNoUnknownKeysRecursive();
  return o;
}

GpioEdgeModel::GpioEdgeModel(const GpioEdgeOptions& options, Time start)
    : options_(options), start_(start) {}

Time GpioEdgeModel::CameraTriggerTime(uint64_t k) const {
  // From the index, not accumulated, so the trigger grid never drifts.
  return start_ + Duration::FromSeconds(options_.camera_phase_s) +
         Duration::Nanoseconds(
             std::llround(static_cast<double>(k) * 1e9 / options_.camera_rate_hz));
}

std::vector<Time> GpioEdgeModel::CameraTriggerTimes(Time begin, Time end) const {
  std::vector<Time> out;
  const double first = (begin - start_).ToSeconds() - options_.camera_phase_s;
  uint64_t k =
      first <= 0.0 ? 0 : static_cast<uint64_t>(std::floor(first * options_.camera_rate_hz));
  while (CameraTriggerTime(k) < begin) ++k;
  for (; CameraTriggerTime(k) < end; ++k) out.push_back(CameraTriggerTime(k));
  return out;
}

std::vector<drivers::GpioEdge> GpioEdgeModel::CameraTriggerEdges(Time begin, Time end) const {
  const Duration width = Duration::FromSeconds(options_.camera_pulse_width_s);
  std::vector<drivers::GpioEdge> out;
  // A pulse that rose before `begin` may still fall inside the window.
  for (const Time rise : CameraTriggerTimes(begin - width, end)) {
    if (rise >= begin) out.push_back({rise, options_.camera_trigger_line, true});
    if (rise + width >= begin && rise + width < end) {
      out.push_back({rise + width, options_.camera_trigger_line, false});
    }
  }
  SortByTime(&out);
  return out;
}

std::array<drivers::GpioEdge, 2> GpioEdgeModel::ImuDataReadyEdges(Time sample_stamp) const {
  const Time rise = sample_stamp + Duration::FromSeconds(options_.imu_data_ready_delay_s);
  const Time fall = rise + Duration::FromSeconds(options_.imu_data_ready_pulse_width_s);
  return {drivers::GpioEdge{rise, options_.imu_data_ready_line, true},
          drivers::GpioEdge{fall, options_.imu_data_ready_line, false}};
}

void GpioEdgeModel::SortByTime(std::vector<drivers::GpioEdge>* edges) {
  std::stable_sort(
      edges->begin(), edges->end(),
      [](const drivers::GpioEdge& a, const drivers::GpioEdge& b) { return a.stamp < b.stamp; });
}

}  // namespace rover::sim
