#ifndef ROVER_ESTIMATOR_IO_LOG_REPLAY_H_
#define ROVER_ESTIMATOR_IO_LOG_REPLAY_H_

// Bit-exact replay of a flight log through the local reference filter: the
// logged inputs (merged back into the filter's input order by their sequence
// numbers) go through a fresh filter built from the logged options, and every
// logged output (EstimatorState, EstimatorFrameSwitch) is compared byte for
// byte with the replayed one.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace rover::estimator::io {

struct ReplayResult {
  uint64_t inputs = 0;             ///< logged inputs fed to the filter
  uint64_t states_compared = 0;    ///< logged states compared with the replay
  uint64_t switches_compared = 0;  ///< logged frame-switch records compared
  uint64_t unlogged_outputs = 0;   ///< replayed outputs the log does not hold (log drops)
  bool bit_exact = false;          ///< every comparison matched and nothing was missing
  /// The first mismatch, or why the replay could not be complete (missing
  /// options, a gap in the input sequence, an undecodable record); empty
  /// when bit-exact.
  std::string first_difference;
  std::vector<std::string> notes;  ///< informational (e.g. outputs the log dropped)
};

/// Replays `path`. `progress`, if set, is called now and then with the
/// fraction done. Throws log::McapError if the file cannot be opened at all.
ReplayResult ReplayLog(const std::string& path,
                       const std::function<void(double fraction)>& progress = {});

}  // namespace rover::estimator::io

#endif  // ROVER_ESTIMATOR_IO_LOG_REPLAY_H_
