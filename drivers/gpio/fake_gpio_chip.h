#ifndef ROVER_DRIVERS_GPIO_FAKE_GPIO_CHIP_H_
#define ROVER_DRIVERS_GPIO_FAKE_GPIO_CHIP_H_

// An in-memory GPIO chip for tests, standing in for the kernel at the
// GpioChip boundary (Debian's kernel ships neither gpio-sim nor gpio-mockup).
// It behaves as the uAPI v1 kernel does where the drivers above depend on it:
//
//  - output lines record every physical level change with its
//    CLOCK_MONOTONIC time (taken inside Set(), where the kernel would change
//    the pin), including the change made by the request itself;
//  - input lines queue edges with the timestamps the test chooses, filtered by
//    the requested edge kinds and inverted for active-low requests, in a FIFO
//    of 16 events that drops the *newest* events when full, silently, like
//    the kernel's kfifo;
//  - Connect() wires an output to an input (a loopback jumper) with a fixed
//    propagation delay;
//  - read and set failures can be injected.
//
// Threads: one thread may drive a line's producer side (InjectEdge or the
// wired output's Set) while another reads it; the FIFO is a lock-free
// single-producer/single-consumer ring. Read the recorded transitions when no
// Set() runs concurrently. Lines must not outlive the chip.

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/time/time.h"
#include "drivers/gpio/gpio_chip.h"

namespace rover::drivers {

class FakeGpioChip final : public GpioChip {
 public:
  /// Events the v1 uAPI kernel keeps per requested line (the lineevent kfifo).
  static constexpr std::size_t kKernelFifoEvents = 16;

  /// A physical level change of an output line.
  struct Transition {
    Time stamp;         ///< CLOCK_MONOTONIC time of the change
    uint32_t line = 0;  ///< line offset
    bool high = false;  ///< physical level after the change
  };

  /// A chip called `name` with `num_lines` lines, recording at most
  /// `max_transitions` output changes (storage is allocated here, so Set()
  /// never allocates; further changes are counted in transitions_overflow()).
  explicit FakeGpioChip(std::string name = "fake-gpiochip", uint32_t num_lines = 64,
                        std::size_t max_transitions = 1 << 14);
  ~FakeGpioChip() override;
  FakeGpioChip(const FakeGpioChip&) = delete;
  FakeGpioChip& operator=(const FakeGpioChip&) = delete;

  /// As the kernel: throws GpioError naming the chip and line for an offset
  /// out of range or a line already requested (by the consumer holding it).
  std::unique_ptr<GpioOutputLine> RequestOutput(const GpioLineRequest& request,
                                                bool initial_active) override;
  /// As the kernel: throws GpioError naming the chip and line for an offset
  /// out of range or a line already requested. The FIFO starts empty.
  std::unique_ptr<GpioEventLine> RequestEdges(const GpioLineRequest& request,
                                              GpioEdges edges) override;
  const std::string& name() const override { return name_; }

  /// Queues a physical edge (`rising`: the pin went high) on input `line`,
  /// stamped `stamp`, as the kernel's interrupt handler would: ignored unless
  /// the line is requested for events and the edge's logical kind (after
  /// active-low inversion) was requested; dropped and counted in
  /// dropped_events() if the FIFO already holds 16 events. Returns true if
  /// the edge was queued. No allocation.
  bool InjectEdge(uint32_t line, Time stamp, bool rising);

  /// Wires output `output_line` to input `input_line`: each physical change
  /// of the output injects the matching edge, stamped `delay` after the
  /// change. Call before the lines are used.
  void Connect(uint32_t output_line, uint32_t input_line, Duration delay = Duration::Zero());

  // The accessors below throw std::out_of_range for a line offset beyond the
  // chip.

  /// The next `count` Set() calls on `line` fail (return false, no change).
  void FailNextSets(uint32_t line, uint32_t count);
  /// The next `count` Read() calls on `line` fail with kError.
  void FailNextReads(uint32_t line, uint32_t count);

  /// Output changes recorded so far, in order, all lines.
  std::vector<Transition> transitions() const;
  /// Output changes of one line, in order.
  std::vector<Transition> transitions(uint32_t line) const;
  /// Changes not recorded because the storage was full.
  uint64_t transitions_overflow() const { return transitions_overflow_.load(); }
  /// Set() calls on `line` that succeeded, including those that did not
  /// change the level.
  uint64_t set_calls(uint32_t line) const;
  /// The physical level of `line` (false if never driven).
  bool physical_level(uint32_t line) const;
  /// Edges dropped on `line` because its FIFO was full.
  uint64_t dropped_events(uint32_t line) const;
  /// Edges waiting in the FIFO of `line`.
  std::size_t queued_events(uint32_t line) const;
  /// Whether `line` is currently requested.
  bool requested(uint32_t line) const;

  /// Per-line state; opaque, defined in fake_gpio_chip.cc.
  struct LineState;

 private:
  class OutputLine;
  class EventLine;

  LineState& State(uint32_t line) const;
  // State() for the test-facing accessors: throws std::out_of_range.
  const LineState& CheckedState(uint32_t line) const;
  void CheckRequestable(const GpioLineRequest& request) const;
  // Sets the physical level, recording the change and feeding a wired input.
  void Drive(uint32_t line, bool high);
  void Record(uint32_t line, Time stamp, bool high);

  std::string name_;
  uint32_t num_lines_;
  std::unique_ptr<LineState[]> lines_;
  std::vector<Transition> transitions_;  // sized at construction
  std::atomic<std::size_t> transition_count_{0};
  std::atomic<uint64_t> transitions_overflow_{0};
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_GPIO_FAKE_GPIO_CHIP_H_
