#ifndef ROVER_DRIVERS_CAMERA_STEREO_FRAME_H_
#define ROVER_DRIVERS_CAMERA_STEREO_FRAME_H_

#include <cstddef>
#include <cstdint>

#include "core/time/time.h"

namespace rover::drivers {

/// A view of an 8-bit mono image owned by the driver's buffer pool.
struct ImageView {
  int width_px = 0;
  int height_px = 0;
  std::size_t stride_bytes = 0;
  const uint8_t* data = nullptr;
};

/// Both exposures of one hardware trigger: they share one capture time.
struct StereoFrame {
  Time stamp;             ///< start of exposure (the trigger edge)
  uint64_t sequence = 0;  ///< trigger count; gaps mean dropped frames
  ImageView cam0;
  ImageView cam1;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_CAMERA_STEREO_FRAME_H_
