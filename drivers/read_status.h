#ifndef ROVER_DRIVERS_READ_STATUS_H_
#define ROVER_DRIVERS_READ_STATUS_H_

namespace rover::drivers {

/// Outcome of a driver read. Drivers never throw on the real-time path.
enum class ReadStatus {
  kOk,           ///< the output holds a new item
  kTimeout,      ///< nothing arrived in time; try again
  kEndOfStream,  ///< replay finished (never returned by hardware drivers)
  kError,        ///< the device failed; see the driver's health counters
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_READ_STATUS_H_
