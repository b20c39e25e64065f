#ifndef ROVER_HOST_EVAL_CAN_FRAMES_CSV_H_
#define ROVER_HOST_EVAL_CAN_FRAMES_CSV_H_

// Recorded CAN traffic in a dataset: mav0/can0/data.csv, as the simulator's
// dataset writer (and a board's CAN recorder) writes it.

#include <string>
#include <vector>

#include "drivers/can/can_frame.h"

namespace rover::host::eval {

/// Reads "#timestamp [ns],id,dlc,data_hex" rows: id as 0x-prefixed 11-bit
/// hex, data as 2 hex digits per byte (empty for dlc 0). Throws
/// rover::eval::EvalError "FILE:LINE: expected ..., found ..." for a
/// malformed row.
std::vector<drivers::CanFrame> ReadCanFramesCsv(const std::string& path);

}  // namespace rover::host::eval

#endif  // ROVER_HOST_EVAL_CAN_FRAMES_CSV_H_
