#ifndef ROVER_CORE_LINK_DDS_DDS_LINK_H_
#define ROVER_CORE_LINK_DDS_DDS_LINK_H_

// A rover's LinkEndpoint on Cyclone DDS (Debian's cyclonedds, its C API):
// the team protocol's datagrams travel on the best-effort topic
// "rover_team_link" (type rover::team::LinkDatagram, team_link.idl), so the
// team's traffic shows in standard DDS tools (ddsperf, a ROS 2 node with the
// same IDL).
//
// The network comes from Cyclone's XML configuration (options.config_xml,
// or CYCLONEDDS_URI when that is empty): on a rover, the radio's interface,
// no multicast, and the other rovers as unicast peers; MakeUnicastConfig
// writes that. Discovery with multicast off needs ParticipantIndex "auto" in
// Cyclone 0.10, which MakeUnicastConfig sets.
//
// Send never blocks (best effort: a datagram the writer cannot take is
// refused and counted). Receive takes what the reader holds. Now is
// CLOCK_MONOTONIC.

#include <memory>
#include <string>
#include <vector>

#include "core/link/link_endpoint.h"

namespace rover::link {

struct DdsLinkOptions {
  RobotId self = 0;
  /// DDS domain of the team (0..230).
  uint32_t domain_id = 0;
  /// Cyclone DDS XML configuration for the domain; empty: CYCLONEDDS_URI
  /// (or Cyclone's defaults, which multicast on the first interface).
  std::string config_xml;
  /// Datagrams the reader keeps per sender before the oldest is dropped.
  int reader_depth = 1024;

  /// Throws std::invalid_argument "DdsLinkOptions.<key>: expected ..., found ...".
  void Validate() const;
};

/// A configuration for one rover: DDS on `interface_name` only, no
/// multicast, the other rovers at `peer_addresses` (IPv4 or host names),
/// datagrams kept under the radio's MTU, peers kept through an hour of
/// silence, and discovery announced every second.
std::string MakeUnicastConfig(const std::string& interface_name,
                              const std::vector<std::string>& peer_addresses);

class DdsLink final : public LinkEndpoint {
 public:
  /// Creates the participant, topic, writer and reader. Throws
  /// std::runtime_error naming the failing call and Cyclone's reason (bad
  /// XML, no such interface, domain in use with another configuration).
  explicit DdsLink(const DdsLinkOptions& options);
  ~DdsLink() override;
  DdsLink(const DdsLink&) = delete;
  DdsLink& operator=(const DdsLink&) = delete;

  RobotId self() const override;
  bool Send(RobotId to, std::span<const uint8_t> bytes) override;
  std::optional<Datagram> Receive() override;
  Time Now() const override;
  LinkStats stats() const override;

  /// Peers the writer has matched (readers of the team topic elsewhere).
  int matched_readers() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rover::link

#endif  // ROVER_CORE_LINK_DDS_DDS_LINK_H_
