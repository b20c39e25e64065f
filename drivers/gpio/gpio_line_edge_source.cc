#include "drivers/gpio/gpio_line_edge_source.h"

#include <stdexcept>

namespace rover::drivers {

void GpioLineEdgeSourceOptions::Validate() const {
  if (consumer.empty() || consumer.size() > 31) {
    throw std::invalid_argument(
        "GpioLineEdgeSourceOptions.consumer: expected 1 to 31 characters, found '" + consumer +
        "'");
  }
  if (nominal_period < Duration::Zero()) {
    throw std::invalid_argument(
        "GpioLineEdgeSourceOptions.nominal_period: expected >= 0 (0 = aperiodic), found " +
        nominal_period.ToString());
  }
}

namespace {

const GpioLineEdgeSourceOptions& Validated(const GpioLineEdgeSourceOptions& options) {
  options.Validate();
  return options;
}

}  // namespace

GpioLineEdgeSource::GpioLineEdgeSource(GpioChip& chip, const GpioLineEdgeSourceOptions& options)
    : options_(Validated(options)),
      line_(chip.RequestEdges(GpioLineRequest{options.line, options.consumer, options.active_low},
                              options.edges)) {}

ReadStatus GpioLineEdgeSource::Wait(GpioEdge* edge, Duration timeout) {
  const ReadStatus status = line_->Read(edge, timeout);
  switch (status) {
    case ReadStatus::kOk:
      Account(*edge);
      break;
    case ReadStatus::kTimeout:
      ++stats_.timeouts;
      break;
    case ReadStatus::kEndOfStream:
    case ReadStatus::kError:
      ++stats_.read_errors;
      return ReadStatus::kError;
  }
  return status;
}

uint64_t GpioLineEdgeSource::MissingInGap(Duration gap) const {
  const int64_t period = options_.nominal_period.nanoseconds();
  if (period <= 0 || gap.nanoseconds() * 2 <= period * 3) return 0;
  // Rounds to whole periods so jitter of up to half a period is tolerated.
  const int64_t periods = (gap.nanoseconds() + period / 2) / period;
  return static_cast<uint64_t>(periods - 1);
}

void GpioLineEdgeSource::Account(const GpioEdge& edge) {
  ++stats_.edges;
  if (have_last_ && edge.stamp < last_stamp_) ++stats_.backward_stamps;
  const bool periodic = options_.nominal_period > Duration::Zero();
  if (options_.edges != GpioEdges::kBoth) {
    if (have_reference_) stats_.lost_edges += MissingInGap(edge.stamp - last_reference_);
    have_reference_ = true;
    last_reference_ = edge.stamp;
  } else if (edge.rising) {
    if (have_reference_) {
      const uint64_t missing_rising = MissingInGap(edge.stamp - last_reference_);
      // One falling edge belongs to each period spanned.
      const uint64_t expected_falling = missing_rising + 1;
      const uint64_t missing_falling = others_since_reference_ < expected_falling
                                           ? expected_falling - others_since_reference_
                                           : 0;
      stats_.lost_edges += missing_rising + missing_falling;
    }
    have_reference_ = true;
    last_reference_ = edge.stamp;
    others_since_reference_ = 0;
  } else {
    // Falling after falling: a rising edge is missing. With a period and a
    // reference, the next rising edge's gap counts it instead.
    if (have_last_ && !last_rising_ && (!periodic || !have_reference_)) ++stats_.lost_edges;
    ++others_since_reference_;
  }
  have_last_ = true;
  last_rising_ = edge.rising;
  last_stamp_ = edge.stamp;
}

}  // namespace rover::drivers
