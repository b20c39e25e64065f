#ifndef ROVER_DRIVERS_GPIO_GPIO_LINE_EDGE_SOURCE_H_
#define ROVER_DRIVERS_GPIO_GPIO_LINE_EDGE_SOURCE_H_

// GpioEdgeSource over one requested input line of a GpioChip (IMU
// data-ready, camera sync-out, PPS): kernel-stamped edges, and an estimate of
// the edges the kernel dropped.
//
// Lost edges. The v1 uAPI kernel queues at most 16 events per line and drops
// new ones when the FIFO is full; its events carry no sequence number. Losses
// are therefore inferred:
//  - from the period, when `nominal_period` is set: a gap between two edges
//    of the reference kind (rising edges when both kinds are requested, else
//    the requested kind) longer than 1.5 periods means round(gap / period) - 1
//    edges of that kind are missing;
//  - from the pattern, when both kinds are requested: between two rising
//    edges there must be one falling edge per period spanned, so each falling
//    edge short of that is missing; two falling edges in a row mean a rising
//    edge is missing (counted at once when no period is set or no rising edge
//    was seen yet, else by the next rising edge's period check, so no edge is
//    counted twice).
// Without a period, an even run of lost edges (whole pulses) cannot be seen.
// A glitch (an extra pulse) is not a loss and is never counted as one.

#include <cstdint>
#include <memory>
#include <string>

#include "core/time/time.h"
#include "drivers/gpio/gpio_chip.h"
#include "drivers/gpio/gpio_edge_source.h"
#include "drivers/gpio/gpio_event_line.h"

namespace rover::drivers {

/// Which line to watch and how.
struct GpioLineEdgeSourceOptions {
  /// Line offset on the chip.
  uint32_t line = 0;
  /// Holder name shown by gpioinfo (1 to 31 characters).
  std::string consumer = "rover-edges";
  /// Edge kinds to report; kBoth enables the pattern check.
  GpioEdges edges = GpioEdges::kBoth;
  /// The signal is active low (rising = the line went low).
  bool active_low = false;
  /// Spacing of successive reference edges of a periodic signal (the IMU's
  /// sample period), or zero for an aperiodic one (no period check).
  Duration nominal_period = Duration::Zero();

  /// Throws std::invalid_argument "GpioLineEdgeSourceOptions.<field>:
  /// expected ..., found ..." for a consumer that is empty or longer than 31
  /// characters, or a negative nominal_period.
  void Validate() const;
};

/// Counters of one edge source. Read them from the thread calling Wait().
struct GpioEdgeSourceStats {
  uint64_t edges = 0;            ///< edges delivered
  uint64_t lost_edges = 0;       ///< edges inferred missing (see the file comment)
  uint64_t timeouts = 0;         ///< Wait() calls that timed out
  uint64_t read_errors = 0;      ///< Wait() calls that failed
  uint64_t backward_stamps = 0;  ///< edges stamped before the previous one
};

class GpioLineEdgeSource final : public GpioEdgeSource {
 public:
  /// Validates `options` (std::invalid_argument) and requests the line on
  /// `chip` (GpioError naming the chip and line). The requested line keeps
  /// what it needs of a LibgpiodChip; a FakeGpioChip must outlive this.
  GpioLineEdgeSource(GpioChip& chip, const GpioLineEdgeSourceOptions& options);

  /// Waits up to `timeout` for the next edge and stores it in *edge: kernel
  /// CLOCK_MONOTONIC stamp, line offset, rising = became active. Updates the
  /// lost-edge estimate. kTimeout and kError are counted in stats(). No
  /// allocation, no lock, never throws.
  ReadStatus Wait(GpioEdge* edge, Duration timeout) override;

  /// Edges inferred lost so far (stats().lost_edges).
  uint64_t lost_edges() const override { return stats_.lost_edges; }
  const GpioEdgeSourceStats& stats() const { return stats_; }
  const GpioLineEdgeSourceOptions& options() const { return options_; }

 private:
  void Account(const GpioEdge& edge);
  // Missing periods in `gap`: round(gap / period) - 1 when gap > 1.5 period.
  uint64_t MissingInGap(Duration gap) const;

  GpioLineEdgeSourceOptions options_;
  std::unique_ptr<GpioEventLine> line_;
  GpioEdgeSourceStats stats_;
  bool have_last_ = false;
  bool last_rising_ = false;
  Time last_stamp_;
  bool have_reference_ = false;
  Time last_reference_;
  uint64_t others_since_reference_ = 0;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_GPIO_GPIO_LINE_EDGE_SOURCE_H_
