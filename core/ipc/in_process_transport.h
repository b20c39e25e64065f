#ifndef ROVER_CORE_IPC_IN_PROCESS_TRANSPORT_H_
#define ROVER_CORE_IPC_IN_PROCESS_TRANSPORT_H_

// Transport within one process, with the semantics of IceoryxTransport (see
// transport.h), for unit tests and log replay without a RouDi daemon.
//
// Design: each topic owns one BroadcastRing, allocated when the first
// endpoint of the topic is created. Publish writes the message once into the
// ring (wait-free, no allocation, independent of the number of subscribers).
// Each subscriber is a cursor into the ring; its queue capacity is how far
// the cursor may lag behind the newest message before the oldest ones count
// as discarded, exactly like an iceoryx queue with DISCARD_OLDEST_DATA.
// History is the part of the ring written since the current publisher was
// created.
//
// Differences from iceoryx, by design:
// * At most one live publisher per topic (a broadcast ring has one writer).
//   A second MakeRawPublisher on the same topic fails until the first
//   publisher is destroyed.
// * Connections are immediate: an endpoint is connected as soon as it exists
//   (iceoryx connects asynchronously through RouDi's discovery loop).
// * Loan() hands out a per-publisher staging buffer (one outstanding loan);
//   PublishLoaned copies it into the ring.
// * queue_capacity and history_capacity are clamped to
//   Options::max_queue_capacity instead of 256 / 16.

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>

#include "core/ipc/transport.h"

namespace rover::ipc {

class InProcessTransport final : public Transport {
 public:
  struct Options {
    /// Largest subscriber queue / publisher history. Every topic preallocates
    /// the next power of two above this many message slots (so memory per
    /// topic is about 2 * max_queue_capacity * message size; lower it for
    /// replaying large messages such as images).
    uint64_t max_queue_capacity = 64;
  };

  /// Creates a transport with default Options.
  InProcessTransport();
  /// Creates a transport; max_queue_capacity is raised to at least 1.
  explicit InProcessTransport(const Options& options);
  ~InProcessTransport() override;

  std::string_view name() const override { return "in-process"; }

  /// Fails if the topic already has a live publisher or was created with a
  /// different message layout.
  std::unique_ptr<RawPublisher> MakeRawPublisher(const Topic& topic, const MessageLayout& layout,
                                                 const PublisherOptions& options,
                                                 std::string* error) override;
  /// Fails if the topic was created with a different message layout or the
  /// options are invalid.
  std::unique_ptr<RawSubscriber> MakeRawSubscriber(const Topic& topic, const MessageLayout& layout,
                                                   const SubscriberOptions& options,
                                                   std::string* error) override;

  struct TopicState;  // Defined in the .cc; public so the endpoints can name it.

 private:
  std::shared_ptr<TopicState> FindOrCreateTopic(const Topic& topic, const MessageLayout& layout,
                                                std::string* error);

  Options options_;
  std::mutex mutex_;  // Guards topics_; only endpoint creation takes it.
  std::map<std::string, std::shared_ptr<TopicState>, std::less<>> topics_;
};

}  // namespace rover::ipc

#endif  // ROVER_CORE_IPC_IN_PROCESS_TRANSPORT_H_
