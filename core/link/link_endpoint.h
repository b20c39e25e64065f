#ifndef ROVER_CORE_LINK_LINK_ENDPOINT_H_
#define ROVER_CORE_LINK_LINK_ENDPOINT_H_

// One rover's end of the team's radio link: unreliable datagrams to one
// other rover or to all of them. What the team protocol (TeamSync) needs
// from a network and nothing more, so that it runs the same over Cyclone DDS
// between boards (DdsLink) and over the deterministic in-process network of
// the tests (EmulatedNetwork).
//
// Datagrams may be lost, duplicated, delayed or reordered; they are never
// corrupted silently (the protocol checks each one anyway). Send never
// blocks: a datagram the endpoint cannot take is refused and counted.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "core/time/time.h"

namespace rover::link {

using RobotId = uint32_t;

/// Addresses every other rover of the team.
inline constexpr RobotId kAllRobots = UINT32_MAX;

/// Largest datagram an endpoint carries: one UDP packet on a 1500-byte link
/// with room for the DDS and IP headers, so that a lost IP fragment never
/// takes a whole datagram with it.
inline constexpr std::size_t kMaxDatagramBytes = 1200;

struct Datagram {
  RobotId from = 0;
  RobotId to = 0;  ///< kAllRobots for a broadcast
  std::vector<uint8_t> bytes;
  Time received;  ///< when it arrived at this endpoint
};

struct LinkStats {
  uint64_t sent = 0;
  uint64_t sent_bytes = 0;
  uint64_t refused = 0;  ///< Send returned false
  uint64_t received = 0;
  uint64_t received_bytes = 0;
};

class LinkEndpoint {
 public:
  virtual ~LinkEndpoint() = default;

  /// This rover's id.
  virtual RobotId self() const = 0;
  /// Queues `bytes` (at most kMaxDatagramBytes) for robot `to` (or
  /// kAllRobots). Returns false, and counts it, if the endpoint cannot take
  /// it: too large, addressed to itself, or its queue is full.
  virtual bool Send(RobotId to, std::span<const uint8_t> bytes) = 0;
  /// The next datagram that has arrived, if any. Never blocks.
  virtual std::optional<Datagram> Receive() = 0;
  /// The endpoint's clock (monotonic on a board, simulated in tests).
  virtual Time Now() const = 0;
  virtual LinkStats stats() const = 0;
};

}  // namespace rover::link

#endif  // ROVER_CORE_LINK_LINK_ENDPOINT_H_
