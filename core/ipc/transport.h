#ifndef ROVER_CORE_IPC_TRANSPORT_H_
#define ROVER_CORE_IPC_TRANSPORT_H_

// Typed publish/subscribe between processes (iceoryx) or within one process
// (tests, log replay), behind one interface.
//
// Messages are trivially copyable structs; they travel as raw bytes, so both
// ends must agree on the C++ type of a topic (sizes are checked, layouts are
// not). Virtual functions cannot be templates, so a Transport implements
// type-erased byte-level endpoints (RawPublisher, RawSubscriber) and the
// typed Publisher<T>/Subscriber<T> are thin adapters over them.
//
// Real-time contract (both transports): Publish, PublishInPlace, TryTake and
// HasMissedData never block and never allocate. Creating and destroying
// endpoints does both; do it at start-up.
//
// Shared semantics (what the tests in tests/core/ipc check for both):
// * A subscriber has a queue of SubscriberOptions::queue_capacity messages.
//   When a message arrives at a full queue the oldest one is discarded and
//   HasMissedData() reports it once. Publishing therefore never waits for a
//   slow subscriber.
// * Publish fails (returns false, dropped() counts it) only when the
//   transport has no buffer for the message.
// * A subscriber that connects to a publisher with history_capacity > 0 first
//   receives up to min(history_request, history_capacity) past messages.
// * Message order per publisher is preserved for every subscriber.
//
// Each endpoint is used by one thread at a time; the statistics accessors
// (published, dropped, taken) may be read from any thread.

#include <atomic>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>

#include "core/ipc/topic.h"

namespace rover::ipc {

/// Types that can be sent: copied byte-wise into shared memory and read back
/// in another process. Pointers would be meaningless there.
template <typename T>
concept Message = std::is_trivially_copyable_v<T> && !std::is_pointer_v<T> &&
                  !std::is_reference_v<T> && sizeof(T) <= UINT32_MAX;

/// Size and alignment of a topic's message type, the type-erased stand-in
/// for T.
struct MessageLayout {
  std::size_t size_bytes = 0;
  std::size_t alignment_bytes = 1;

  template <Message T>
  static constexpr MessageLayout Of() {
    return MessageLayout{sizeof(T), alignof(T)};
  }
  friend bool operator==(const MessageLayout&, const MessageLayout&) = default;
};

struct PublisherOptions {
  /// Number of most recent messages kept for subscribers that connect later
  /// and ask for history. 0 disables history. iceoryx caps it at 16.
  uint64_t history_capacity = 0;
};

struct SubscriberOptions {
  /// Messages queued for this subscriber before the oldest is discarded.
  /// At least 1; iceoryx caps it at 256, the in-process transport at its
  /// Options::max_queue_capacity.
  uint64_t queue_capacity = 16;
  /// Past messages to receive on connection (bounded by the publisher's
  /// history_capacity).
  uint64_t history_request = 0;
};

/// Byte-level publisher; obtain one from Transport::MakeRawPublisher.
class RawPublisher {
 public:
  virtual ~RawPublisher() = default;
  RawPublisher(const RawPublisher&) = delete;
  RawPublisher& operator=(const RawPublisher&) = delete;

  /// Layout of the messages this publisher sends.
  const MessageLayout& layout() const { return layout_; }

  /// Copies layout().size_bytes bytes from `message` into a transport buffer
  /// and publishes them. Never blocks or allocates. Returns false, and counts
  /// a drop, if no buffer is available.
  virtual bool Publish(const void* message) = 0;

  /// Lends a transport buffer of layout().size_bytes bytes, aligned to
  /// layout().alignment_bytes, with unspecified contents, to be filled in
  /// place (with iceoryx it is the shared-memory chunk itself: zero-copy).
  /// Returns nullptr, and counts a drop, if none is available (iceoryx: at
  /// most 8 loans outstanding per publisher, or the mempool is exhausted;
  /// in-process: 1). Never blocks or allocates. Each loan must be passed to
  /// exactly one of PublishLoaned or ReleaseLoan.
  virtual void* Loan() = 0;
  /// Publishes a buffer from Loan(). The caller must not touch it afterwards.
  virtual void PublishLoaned(void* loaned) = 0;
  /// Gives a buffer from Loan() back without publishing it.
  virtual void ReleaseLoan(void* loaned) = 0;

  /// True if at least one subscriber is connected.
  virtual bool HasSubscribers() const = 0;

  /// Messages published since creation. Any thread.
  uint64_t published() const { return published_.load(std::memory_order_relaxed); }
  /// Publish/Loan calls that failed for lack of a buffer. Any thread.
  uint64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }

 protected:
  explicit RawPublisher(const MessageLayout& layout) : layout_(layout) {}
  // Single writer (the publishing thread), so no read-modify-write needed.
  void CountPublished() {
    published_.store(published_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  }
  void CountDropped() {
    dropped_.store(dropped_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  }

 private:
  MessageLayout layout_;
  std::atomic<uint64_t> published_{0};
  std::atomic<uint64_t> dropped_{0};
};

/// Byte-level subscriber; obtain one from Transport::MakeRawSubscriber.
class RawSubscriber {
 public:
  virtual ~RawSubscriber() = default;
  RawSubscriber(const RawSubscriber&) = delete;
  RawSubscriber& operator=(const RawSubscriber&) = delete;

  /// Layout of the messages this subscriber receives.
  const MessageLayout& layout() const { return layout_; }

  /// Copies the oldest queued message (layout().size_bytes bytes) into `out`
  /// and removes it from the queue. Returns false if the queue is empty.
  /// Never blocks or allocates. Messages of the wrong size (a publisher
  /// built with a different type) are discarded and reported through
  /// HasMissedData().
  virtual bool TryTake(void* out) = 0;

  /// True if messages for this subscriber were discarded since the last call
  /// (queue overflow, or wrong size); the indication is reset by the call.
  /// Never blocks or allocates.
  virtual bool HasMissedData() = 0;

  /// True if at least one publisher offers the topic. iceoryx learns this
  /// asynchronously from RouDi's service registry (and the query locks and
  /// scans it): poll it for health checks and start-up, not from a
  /// real-time loop.
  virtual bool HasPublishers() const = 0;

  /// Messages returned by TryTake since creation. Any thread.
  uint64_t taken() const { return taken_.load(std::memory_order_relaxed); }

 protected:
  explicit RawSubscriber(const MessageLayout& layout) : layout_(layout) {}
  void CountTaken() {
    taken_.store(taken_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  }

 private:
  MessageLayout layout_;
  std::atomic<uint64_t> taken_{0};
};

/// Typed publisher of T. Abstract so that components can be tested against a
/// mock; Transport::MakePublisher returns the real one.
template <Message T>
class Publisher {
 public:
  virtual ~Publisher() = default;

  /// Copies `msg` into a transport buffer and publishes it. Never blocks,
  /// never allocates. Returns false, and counts a drop, if no buffer is
  /// available.
  virtual bool Publish(const T& msg) = 0;

  /// Builds the message in place: calls `fill(T&)` on a default-initialised
  /// T living in the transport's buffer (shared memory with iceoryx, so large
  /// messages are written exactly once), then publishes it. Returns false,
  /// counts a drop and does not call `fill` if no buffer is available.
  template <typename Fill>
  requires std::is_invocable_v<Fill&, T&> && std::is_default_constructible_v<T>
  bool PublishInPlace(Fill&& fill) {
    void* buffer = LoanBuffer();
    if (buffer == nullptr) {
      return false;
    }
    T* msg = ::new (buffer) T;
    fill(*msg);
    PublishBuffer(buffer);
    return true;
  }

  /// Messages published since creation. Any thread.
  virtual uint64_t published() const = 0;
  /// Messages dropped for lack of a transport buffer. Any thread.
  virtual uint64_t dropped() const = 0;
  /// True if at least one subscriber is connected.
  virtual bool HasSubscribers() const = 0;

 protected:
  /// A buffer for one T (see RawPublisher::Loan), or nullptr after counting
  /// a drop.
  virtual void* LoanBuffer() = 0;
  /// Publishes a buffer from LoanBuffer().
  virtual void PublishBuffer(void* buffer) = 0;
};

/// Typed subscriber of T.
template <Message T>
class Subscriber {
 public:
  virtual ~Subscriber() = default;

  /// Copies the oldest queued message into `*out` and removes it. Returns
  /// false if none is queued. Never blocks, never allocates.
  virtual bool TryTake(T* out) = 0;
  /// True if messages were discarded since the last call (queue overflow);
  /// resets the indication.
  virtual bool HasMissedData() = 0;
  /// True if at least one publisher offers the topic (see
  /// RawSubscriber::HasPublishers; not for real-time loops).
  virtual bool HasPublishers() const = 0;
  /// Messages taken since creation. Any thread.
  virtual uint64_t taken() const = 0;
};

namespace internal {

// The one implementation of Publisher<T>: forwards to the byte-level port.
template <Message T>
class TypedPublisher final : public Publisher<T> {
 public:
  explicit TypedPublisher(std::unique_ptr<RawPublisher> raw) : raw_(std::move(raw)) {}
  bool Publish(const T& msg) override { return raw_->Publish(&msg); }
  uint64_t published() const override { return raw_->published(); }
  uint64_t dropped() const override { return raw_->dropped(); }
  bool HasSubscribers() const override { return raw_->HasSubscribers(); }

 protected:
  void* LoanBuffer() override { return raw_->Loan(); }
  void PublishBuffer(void* buffer) override { raw_->PublishLoaned(buffer); }

 private:
  std::unique_ptr<RawPublisher> raw_;
};

template <Message T>
class TypedSubscriber final : public Subscriber<T> {
 public:
  explicit TypedSubscriber(std::unique_ptr<RawSubscriber> raw) : raw_(std::move(raw)) {}
  bool TryTake(T* out) override { return raw_->TryTake(out); }
  bool HasMissedData() override { return raw_->HasMissedData(); }
  bool HasPublishers() const override { return raw_->HasPublishers(); }
  uint64_t taken() const override { return raw_->taken(); }

 private:
  std::unique_ptr<RawSubscriber> raw_;
};

}  // namespace internal

/// Factory for endpoints. Endpoints may outlive the Transport that made them.
class Transport {
 public:
  virtual ~Transport() = default;

  /// Short name for logs and test names: "iceoryx", "in-process".
  virtual std::string_view name() const = 0;

  /// Creates a publisher of T on `topic`. Returns nullptr, with the reason in
  /// `*error` if given, if the transport refuses (see the implementations).
  template <Message T>
  std::unique_ptr<Publisher<T>> MakePublisher(const Topic& topic,
                                              const PublisherOptions& options = {},
                                              std::string* error = nullptr) {
    std::unique_ptr<RawPublisher> raw =
        MakeRawPublisher(topic, MessageLayout::Of<T>(), options, error);
    if (raw == nullptr) {
      return nullptr;
    }
    return std::make_unique<internal::TypedPublisher<T>>(std::move(raw));
  }

  /// Creates a subscriber of T on `topic`. Returns nullptr, with the reason
  /// in `*error` if given, if the transport refuses.
  template <Message T>
  std::unique_ptr<Subscriber<T>> MakeSubscriber(const Topic& topic,
                                                const SubscriberOptions& options = {},
                                                std::string* error = nullptr) {
    std::unique_ptr<RawSubscriber> raw =
        MakeRawSubscriber(topic, MessageLayout::Of<T>(), options, error);
    if (raw == nullptr) {
      return nullptr;
    }
    return std::make_unique<internal::TypedSubscriber<T>>(std::move(raw));
  }

  /// Byte-level publisher for messages of `layout`. nullptr (reason in
  /// `*error` if given) on failure. Allocates; not for real-time threads.
  virtual std::unique_ptr<RawPublisher> MakeRawPublisher(const Topic& topic,
                                                         const MessageLayout& layout,
                                                         const PublisherOptions& options,
                                                         std::string* error) = 0;
  /// Byte-level subscriber for messages of `layout`. nullptr (reason in
  /// `*error` if given) on failure. Allocates; not for real-time threads.
  virtual std::unique_ptr<RawSubscriber> MakeRawSubscriber(const Topic& topic,
                                                           const MessageLayout& layout,
                                                           const SubscriberOptions& options,
                                                           std::string* error) = 0;

 protected:
  /// Checks what both transports require of a layout and subscriber options;
  /// returns false with a reason in `*error` (if given) otherwise.
  static bool ValidateLayout(const MessageLayout& layout, std::string* error);
  static bool ValidateSubscriberOptions(const SubscriberOptions& options, std::string* error);
  /// Stores `message` in `*error` if `error` is not null. Returns false, so
  /// callers can `return SetError(...)` style in bool contexts.
  static bool SetError(std::string* error, std::string message);
};

}  // namespace rover::ipc

#endif  // ROVER_CORE_IPC_TRANSPORT_H_
