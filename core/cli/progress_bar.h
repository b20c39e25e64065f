#ifndef ROVER_CORE_CLI_PROGRESS_BAR_H_
#define ROVER_CORE_CLI_PROGRESS_BAR_H_

// Progress of long host-tool work counted in items (cells of a table,
// frames of a log): on a terminal one bar redrawn in place at most a few
// times a second with the rate and the time left; otherwise one line per
// tenth, so a log file does not fill with carriage returns.

#include <chrono>
#include <cstdint>
#include <ostream>
#include <string>

namespace rover::cli {

class ProgressBar {
 public:
  /// `unit` names the items ("cells"); `tty`: draw the bar in place.
  ProgressBar(std::ostream& out, std::string name, uint64_t total, std::string unit, bool tty);

  /// `done` items so far (monotonic).
  void Update(uint64_t done);
  /// Draws the final state and ends the line.
  void Finish();

  /// "1m05s", "2h03m", "--" for an unknown (non-finite or negative) time.
  static std::string FormatDuration(double seconds);

 private:
  using Clock = std::chrono::steady_clock;
  void Draw(bool final);

  std::ostream& out_;
  const std::string name_;
  const uint64_t total_;
  const std::string unit_;
  const bool tty_;
  const Clock::time_point start_;
  Clock::time_point last_draw_;
  uint64_t done_ = 0;
  int next_tenth_ = 1;
};

}  // namespace rover::cli

#endif  // ROVER_CORE_CLI_PROGRESS_BAR_H_
