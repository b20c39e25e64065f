#ifndef ROVER_CORE_LINK_EMULATED_NETWORK_H_
#define ROVER_CORE_LINK_EMULATED_NETWORK_H_

// An in-process radio network for tests and for the team protocol's
// benchmarks: every rover gets a LinkEndpoint, and each direction between
// two rovers has its own conditions, modelled on Linux's netem (one-way
// delay and jitter, random loss, a rate limit with a bounded queue, and
// outages during which nothing gets through).
//
// Time is simulated: nothing moves until AdvanceTo, and the same seed,
// conditions and calls give the same deliveries, so tests of loss and
// outages are exact and fast. Datagrams sent at the same instant leave in
// the order sent; jitter may reorder them, as it does on a real link.
//
// Not thread-safe: one thread drives the network and all its endpoints.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <queue>
#include <random>
#include <utility>
#include <vector>

#include "core/link/link_endpoint.h"

namespace rover::link {

/// A time during which a direction of the link carries nothing.
struct Outage {
  Time start;
  Time end;  ///< exclusive
};

/// One direction of one link.
struct LinkConditions {
  Duration delay = Duration::Zero();   ///< one way
  Duration jitter = Duration::Zero();  ///< uniform extra delay in [0, jitter)
  double loss = 0.0;                   ///< probability that a datagram is lost
  /// 0: unlimited. Otherwise datagrams leave one after another at this rate.
  double rate_bytes_per_s = 0.0;
  /// With a rate limit: a datagram that would wait behind more than this
  /// many bytes is dropped (netem's limit, in bytes).
  std::size_t queue_bytes = 256 * 1024;
  std::vector<Outage> outages;

  /// Throws std::invalid_argument "LinkConditions.<key>: expected ..., found ...".
  void Validate() const;
};

/// What one direction did.
struct DirectionStats {
  uint64_t sent = 0;
  uint64_t delivered = 0;
  uint64_t lost = 0;           ///< random loss
  uint64_t dropped_queue = 0;  ///< behind a full queue
  uint64_t dropped_outage = 0;
  uint64_t delivered_bytes = 0;
};

class EmulatedNetwork {
 public:
  /// `seed` drives loss and jitter; `start` is the clock's first value.
  explicit EmulatedNetwork(uint64_t seed, Time start = Time::Zero());
  ~EmulatedNetwork();
  EmulatedNetwork(const EmulatedNetwork&) = delete;
  EmulatedNetwork& operator=(const EmulatedNetwork&) = delete;

  /// A new endpoint for rover `id`; it must outlive no network. Throws
  /// std::invalid_argument for an id already joined or kAllRobots.
  std::unique_ptr<LinkEndpoint> Join(RobotId id);

  /// The conditions from `from` to `to` (default: perfect, no delay).
  /// Throws std::invalid_argument for invalid conditions.
  void SetConditions(RobotId from, RobotId to, const LinkConditions& conditions);
  /// Both directions between `a` and `b`.
  void SetConditionsBothWays(RobotId a, RobotId b, const LinkConditions& conditions);

  /// Moves the clock to `now` (never backwards) and hands every datagram
  /// that has arrived by then to its endpoint.
  void AdvanceTo(Time now);
  Time now() const { return now_; }

  DirectionStats stats(RobotId from, RobotId to) const;

 private:
  class Endpoint;
  struct InFlight {
    Time arrival;
    uint64_t order = 0;  // ties leave in sending order
    Datagram datagram;
    bool operator>(const InFlight& o) const {
      return arrival != o.arrival ? arrival > o.arrival : order > o.order;
    }
  };
  struct Direction {
    LinkConditions conditions;
    Time free_at;  // when the rate-limited link finishes what it holds
    DirectionStats stats;
  };

  bool Send(RobotId from, RobotId to, std::span<const uint8_t> bytes);
  void SendOne(RobotId from, RobotId to, std::span<const uint8_t> bytes);
  Direction& DirectionOf(RobotId from, RobotId to);

  std::mt19937_64 rng_;
  Time now_;
  uint64_t order_ = 0;
  std::map<RobotId, Endpoint*> endpoints_;
  std::map<std::pair<RobotId, RobotId>, Direction> directions_;
  std::priority_queue<InFlight, std::vector<InFlight>, std::greater<>> in_flight_;
};

}  // namespace rover::link

#endif  // ROVER_CORE_LINK_EMULATED_NETWORK_H_
