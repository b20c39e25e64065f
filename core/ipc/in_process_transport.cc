#include "core/ipc/in_process_transport.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstring>
#include <new>
#include <utility>

#include "core/ring/broadcast_ring.h"

namespace rover::ipc {

struct InProcessTransport::TopicState {
  TopicState(const MessageLayout& message_layout, std::size_t ring_capacity)
      : layout(message_layout), ring(message_layout.size_bytes, ring_capacity) {}

  const MessageLayout layout;
  BroadcastRing ring;

  // Guards the publisher hand-over below. Never taken by Publish or TryTake;
  // it also orders one publisher's ring writes before the next one's.
  std::mutex mutex;
  bool has_publisher = false;          // guarded by mutex
  uint64_t history_capacity = 0;       // guarded by mutex
  uint64_t publisher_first_index = 0;  // guarded by mutex

  // Connection state for HasPublishers/HasSubscribers, read lock-free.
  std::atomic<bool> publisher_alive{false};
  std::atomic<uint32_t> subscriber_count{0};
};

namespace {

using TopicState = InProcessTransport::TopicState;

struct AlignedFree {
  std::size_t alignment_bytes;
  void operator()(void* ptr) const { ::operator delete (ptr, std::align_val_t{alignment_bytes}); }
};

class InProcessPublisher final : public RawPublisher {
 public:
  explicit InProcessPublisher(std::shared_ptr<TopicState> topic)
      : RawPublisher(topic->layout),
        topic_(std::move(topic)),
        staging_(::operator new (layout().size_bytes, std::align_val_t{layout().alignment_bytes}),
                 AlignedFree{layout().alignment_bytes}) {}

  ~InProcessPublisher() override {
    std::lock_guard<std::mutex> lock(topic_->mutex);
    topic_->has_publisher = false;
    topic_->publisher_alive.store(false, std::memory_order_relaxed);
  }

  bool Publish(const void* message) override {
    topic_->ring.Write(message);
    CountPublished();
    return true;
  }

  void* Loan() override {
    if (loaned_) {
      CountDropped();
      return nullptr;
    }
    loaned_ = true;
    return staging_.get();
  }

  void PublishLoaned(void* loaned) override {
    Publish(loaned);
    loaned_ = false;
  }

  void ReleaseLoan(void* /*loaned*/) override { loaned_ = false; }

  bool HasSubscribers() const override {
    return topic_->subscriber_count.load(std::memory_order_relaxed) > 0;
  }

 private:
  std::shared_ptr<TopicState> topic_;
  std::unique_ptr<void, AlignedFree> staging_;
  bool loaned_ = false;
};

class InProcessSubscriber final : public RawSubscriber {
 public:
  InProcessSubscriber(std::shared_ptr<TopicState> topic, uint64_t queue_capacity,
                      BroadcastRing::Cursor cursor)
      : RawSubscriber(topic->layout),
        topic_(std::move(topic)),
        queue_capacity_(queue_capacity),
        cursor_(cursor) {
    topic_->subscriber_count.fetch_add(1, std::memory_order_relaxed);
  }

  ~InProcessSubscriber() override {
    topic_->subscriber_count.fetch_sub(1, std::memory_order_relaxed);
  }

  bool TryTake(void* out) override {
    uint64_t skipped = 0;
    const bool taken = topic_->ring.ReadNext(&cursor_, queue_capacity_, out, &skipped);
    missed_ = missed_ || skipped > 0;
    if (taken) {
      CountTaken();
    }
    return taken;
  }

  bool HasMissedData() override {
    // iceoryx flags an overflow when it happens, not when the subscriber next
    // takes; emulate that by applying the queue window now.
    const uint64_t head = topic_->ring.write_count();
    if (head - cursor_.next_index > queue_capacity_) {
      cursor_.next_index = head - queue_capacity_;
      missed_ = true;
    }
    return std::exchange(missed_, false);
  }

  bool HasPublishers() const override {
    return topic_->publisher_alive.load(std::memory_order_relaxed);
  }

 private:
  std::shared_ptr<TopicState> topic_;
  uint64_t queue_capacity_;
  BroadcastRing::Cursor cursor_;
  bool missed_ = false;
};

}  // namespace

InProcessTransport::InProcessTransport() : InProcessTransport(Options{}) {}

InProcessTransport::InProcessTransport(const Options& options) : options_(options) {
  options_.max_queue_capacity = std::max<uint64_t>(options_.max_queue_capacity, 1);
}

InProcessTransport::~InProcessTransport() = default;

std::shared_ptr<InProcessTransport::TopicState> InProcessTransport::FindOrCreateTopic(
    const Topic& topic, const MessageLayout& layout, std::string* error) {
  if (!ValidateLayout(layout, error)) {
    return nullptr;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = topics_.find(topic.Key());
  if (it == topics_.end()) {
    // One spare slot: the slot of the oldest queued message is the one the
    // writer overwrites next.
    const std::size_t ring_capacity = std::bit_ceil(options_.max_queue_capacity + 1);
    it = topics_.emplace(topic.Key(), std::make_shared<TopicState>(layout, ring_capacity)).first;
  } else if (!(it->second->layout == layout)) {
    SetError(error, "topic " + topic.name() + " carries messages of " +
                        std::to_string(it->second->layout.size_bytes) + " bytes, not " +
                        std::to_string(layout.size_bytes));
    return nullptr;
  }
  return it->second;
}

std::unique_ptr<RawPublisher> InProcessTransport::MakeRawPublisher(const Topic& topic,
                                                                   const MessageLayout& layout,
                                                                   const PublisherOptions& options,
                                                                   std::string* error) {
  std::shared_ptr<TopicState> state = FindOrCreateTopic(topic, layout, error);
  if (state == nullptr) {
    return nullptr;
  }
  {
    std::lock_guard<std::mutex> lock(state->mutex);
    if (state->has_publisher) {
      SetError(error, "topic " + topic.name() +
                          " already has a publisher (the in-process transport allows one)");
      return nullptr;
    }
    state->has_publisher = true;
    state->history_capacity = std::min(options.history_capacity, options_.max_queue_capacity);
    state->publisher_first_index = state->ring.write_count();
    state->publisher_alive.store(true, std::memory_order_relaxed);
  }
  return std::make_unique<InProcessPublisher>(std::move(state));
}

std::unique_ptr<RawSubscriber> InProcessTransport::MakeRawSubscriber(
    const Topic& topic, const MessageLayout& layout, const SubscriberOptions& options,
    std::string* error) {
  if (!ValidateSubscriberOptions(options, error)) {
    return nullptr;
  }
  std::shared_ptr<TopicState> state = FindOrCreateTopic(topic, layout, error);
  if (state == nullptr) {
    return nullptr;
  }
  const uint64_t queue_capacity = std::min(options.queue_capacity, options_.max_queue_capacity);
  BroadcastRing::Cursor cursor;
  {
    std::lock_guard<std::mutex> lock(state->mutex);
    uint64_t backlog = 0;
    if (state->has_publisher) {
      const uint64_t published_by_current =
          state->ring.write_count() - state->publisher_first_index;
      backlog = std::min(
          {options.history_request, state->history_capacity, published_by_current, queue_capacity});
    }
    cursor = state->ring.MakeCursor(backlog);
  }
  return std::make_unique<InProcessSubscriber>(std::move(state), queue_capacity, cursor);
}

}  // namespace rover::ipc
