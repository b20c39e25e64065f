#include "drivers/gpio/fake_gpio_chip.h"

#include <time.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <utility>

namespace rover::drivers {

struct FakeGpioChip::LineState {
  // A queued event as the kernel stores it: logical kind, kernel stamp.
  struct Event {
    Time stamp;
    bool rising = false;
  };

  std::atomic<bool> requested{false};
  std::string consumer;
  bool is_output = false;
  bool active_low = false;
  GpioEdges edges = GpioEdges::kBoth;
  std::atomic<bool> high{false};
  std::atomic<uint64_t> set_calls{0};
  std::atomic<uint32_t> fail_sets{0};
  std::atomic<uint32_t> fail_reads{0};
  // Single-producer/single-consumer ring of kKernelFifoEvents events;
  // head and tail count events ever written and read.
  std::array<Event, kKernelFifoEvents> fifo{};
  std::atomic<uint64_t> head{0};
  std::atomic<uint64_t> tail{0};
  std::atomic<uint64_t> dropped{0};
  int64_t wired_to = -1;
  Duration wire_delay;
};

namespace {

// Consumes one injected failure, if any is pending.
bool TakeOne(std::atomic<uint32_t>& pending) {
  uint32_t n = pending.load(std::memory_order_relaxed);
  while (n > 0) {
    if (pending.compare_exchange_weak(n, n - 1, std::memory_order_relaxed)) return true;
  }
  return false;
}

// now + timeout without overflowing for Duration::Max() (a day is forever
// for a test double).
Time DeadlineAfter(Time now, Duration timeout) {
  const Duration longest = Duration::Seconds(86'400);
  if (timeout < Duration::Zero()) timeout = Duration::Zero();
  return now + (timeout > longest ? longest : timeout);
}

}  // namespace

class FakeGpioChip::OutputLine final : public GpioOutputLine {
 public:
  OutputLine(FakeGpioChip* chip, uint32_t line) : chip_(chip), line_(line) {}
  ~OutputLine() override { chip_->State(line_).requested.store(false); }
  OutputLine(const OutputLine&) = delete;
  OutputLine& operator=(const OutputLine&) = delete;

  bool Set(bool active) override {
    LineState& state = chip_->State(line_);
    if (TakeOne(state.fail_sets)) return false;
    state.set_calls.fetch_add(1, std::memory_order_relaxed);
    chip_->Drive(line_, active != state.active_low);
    return true;
  }
  uint32_t line() const override { return line_; }

 private:
  FakeGpioChip* chip_;
  uint32_t line_;
};

class FakeGpioChip::EventLine final : public GpioEventLine {
 public:
  EventLine(FakeGpioChip* chip, uint32_t line) : chip_(chip), line_(line) {}
  ~EventLine() override { chip_->State(line_).requested.store(false); }
  EventLine(const EventLine&) = delete;
  EventLine& operator=(const EventLine&) = delete;

  ReadStatus Read(GpioEdge* edge, Duration timeout) override {
    LineState& state = chip_->State(line_);
    const Time deadline = DeadlineAfter(Time::Now(), timeout);
    for (;;) {
      if (TakeOne(state.fail_reads)) return ReadStatus::kError;
      const uint64_t tail = state.tail.load(std::memory_order_relaxed);
      if (tail != state.head.load(std::memory_order_acquire)) {
        const LineState::Event event = state.fifo[tail % kKernelFifoEvents];
        state.tail.store(tail + 1, std::memory_order_release);
        edge->stamp = event.stamp;
        edge->line = line_;
        edge->rising = event.rising;
        return ReadStatus::kOk;
      }
      const Time now = Time::Now();
      if (now >= deadline) return ReadStatus::kTimeout;
      // Polls in short naps: a test double needs no wake-up mechanism, and
      // a nap never allocates or locks.
      const int64_t nap_ns = std::min<int64_t>((deadline - now).nanoseconds(), 50'000);
      const timespec nap{0, static_cast<long>(nap_ns)};
      nanosleep(&nap, nullptr);
    }
  }
  uint32_t line() const override { return line_; }

 private:
  FakeGpioChip* chip_;
  uint32_t line_;
};

FakeGpioChip::FakeGpioChip(std::string name, uint32_t num_lines, std::size_t max_transitions)
    : name_(std::move(name)),
      num_lines_(num_lines),
      lines_(std::make_unique<LineState[]>(num_lines)),
      transitions_(max_transitions) {}

FakeGpioChip::~FakeGpioChip() = default;

FakeGpioChip::LineState& FakeGpioChip::State(uint32_t line) const { return lines_[line]; }

const FakeGpioChip::LineState& FakeGpioChip::CheckedState(uint32_t line) const {
  if (line >= num_lines_) {
    throw std::out_of_range("GPIO " + name_ + ": expected a line offset below " +
                            std::to_string(num_lines_) + ", found " + std::to_string(line));
  }
  return lines_[line];
}

void FakeGpioChip::CheckRequestable(const GpioLineRequest& request) const {
  const std::string who = "GPIO " + name_ + " line " + std::to_string(request.line);
  if (request.line >= num_lines_) {
    throw GpioError(who + ": expected a line offset below " + std::to_string(num_lines_) +
                    " (the chip's line count), found " + std::to_string(request.line));
  }
  if (request.consumer.empty() || request.consumer.size() > 31) {
    throw GpioError(who + ": consumer: expected 1 to 31 characters, found '" + request.consumer +
                    "'");
  }
  const LineState& state = State(request.line);
  if (state.requested.load()) {
    throw GpioError(who + ": cannot request it for consumer '" + request.consumer +
                    "' (expected a free line; it is held by '" + state.consumer +
                    "'): " + std::strerror(EBUSY));
  }
}

std::unique_ptr<GpioOutputLine> FakeGpioChip::RequestOutput(const GpioLineRequest& request,
                                                            bool initial_active) {
  CheckRequestable(request);
  LineState& state = State(request.line);
  state.consumer = request.consumer;
  state.is_output = true;
  state.active_low = request.active_low;
  state.set_calls.store(0);
  state.requested.store(true);
  Drive(request.line, initial_active != request.active_low);
  return std::make_unique<OutputLine>(this, request.line);
}

std::unique_ptr<GpioEventLine> FakeGpioChip::RequestEdges(const GpioLineRequest& request,
                                                          GpioEdges edges) {
  CheckRequestable(request);
  LineState& state = State(request.line);
  state.consumer = request.consumer;
  state.is_output = false;
  state.active_low = request.active_low;
  state.edges = edges;
  state.head.store(0);
  state.tail.store(0);
  state.dropped.store(0);
  state.requested.store(true);
  return std::make_unique<EventLine>(this, request.line);
}

bool FakeGpioChip::InjectEdge(uint32_t line, Time stamp, bool rising) {
  if (line >= num_lines_) return false;
  LineState& state = State(line);
  if (!state.requested.load(std::memory_order_acquire) || state.is_output) return false;
  const bool active = rising != state.active_low;
  if ((state.edges == GpioEdges::kRising && !active) ||
      (state.edges == GpioEdges::kFalling && active)) {
    return false;  // the kernel never enabled the interrupt for this kind
  }
  const uint64_t head = state.head.load(std::memory_order_relaxed);
  if (head - state.tail.load(std::memory_order_acquire) >= kKernelFifoEvents) {
    // kfifo_in fails on a full FIFO: the new event is lost, the old kept.
    state.dropped.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  state.fifo[head % kKernelFifoEvents] = LineState::Event{stamp, active};
  state.head.store(head + 1, std::memory_order_release);
  return true;
}

void FakeGpioChip::Connect(uint32_t output_line, uint32_t input_line, Duration delay) {
  if (output_line >= num_lines_ || input_line >= num_lines_) {
    throw GpioError("GPIO " + name_ + ": cannot wire line " + std::to_string(output_line) +
                    " to line " + std::to_string(input_line) + ": expected offsets below " +
                    std::to_string(num_lines_));
  }
  State(output_line).wired_to = input_line;
  State(output_line).wire_delay = delay;
}

void FakeGpioChip::Drive(uint32_t line, bool high) {
  LineState& state = State(line);
  if (state.high.exchange(high) == high) return;  // no physical change, no edge
  const Time now = Time::Now();
  Record(line, now, high);
  if (state.wired_to >= 0) {
    InjectEdge(static_cast<uint32_t>(state.wired_to), now + state.wire_delay, high);
  }
}

void FakeGpioChip::Record(uint32_t line, Time stamp, bool high) {
  const std::size_t index = transition_count_.fetch_add(1, std::memory_order_relaxed);
  if (index >= transitions_.size()) {
    transitions_overflow_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  transitions_[index] = Transition{stamp, line, high};
}

void FakeGpioChip::FailNextSets(uint32_t line, uint32_t count) {
  CheckedState(line);
  State(line).fail_sets.store(count);
}

void FakeGpioChip::FailNextReads(uint32_t line, uint32_t count) {
  CheckedState(line);
  State(line).fail_reads.store(count);
}

std::vector<FakeGpioChip::Transition> FakeGpioChip::transitions() const {
  const std::size_t n = std::min(transition_count_.load(), transitions_.size());
  return std::vector<Transition>(transitions_.begin(),
                                 transitions_.begin() + static_cast<std::ptrdiff_t>(n));
}

std::vector<FakeGpioChip::Transition> FakeGpioChip::transitions(uint32_t line) const {
  std::vector<Transition> out;
  for (const Transition& t : transitions()) {
    if (t.line == line) out.push_back(t);
  }
  return out;
}

uint64_t FakeGpioChip::set_calls(uint32_t line) const {
  return CheckedState(line).set_calls.load();
}

bool FakeGpioChip::physical_level(uint32_t line) const { return CheckedState(line).high.load(); }

uint64_t FakeGpioChip::dropped_events(uint32_t line) const {
  return CheckedState(line).dropped.load();
}

std::size_t FakeGpioChip::queued_events(uint32_t line) const {
  const LineState& state = CheckedState(line);
  return static_cast<std::size_t>(state.head.load() - state.tail.load());
}

bool FakeGpioChip::requested(uint32_t line) const { return CheckedState(line).requested.load(); }

}  // namespace rover::drivers
