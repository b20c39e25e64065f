#ifndef ROVER_FIRMWARE_MAPD_TEAM_CONFIG_H_
#define ROVER_FIRMWARE_MAPD_TEAM_CONFIG_H_

// The team file: who is in the team and how the rovers reach each other. One
// file for the whole team, the same on every rover; each rover finds itself
// in it by its robot id (mapd --robot-id). For example
//
//   domain_id: 0                   # the team's DDS domain
//   robots:
//     - {id: 0, name: rover_a, address: 10.77.0.1, interface: r1}
//     - {id: 1, name: rover_b, address: 10.77.0.2, interface: r2}
//   link:                          # optional: the team protocol (TeamSync)
//     budget_bytes_per_s: 30000    # what each rover sends at most, on average
//     burst_bytes: 12000
//     summary_interval_s: 0.5
//     min_resend_s: 1.0
//     initial_round_trip_s: 1.0
//     peer_silence_s: 10
//
// `address` is where the other rovers reach this one (IPv4 or a host name);
// `interface` is this rover's radio interface (DDS uses that one only).

#include <cstdint>
#include <string>
#include <vector>

#include "core/config/config.h"
#include "firmware/mapd/team_worker.h"

namespace rover::mapd {

/// One rover of the team.
struct TeamMember {
  int id = 0;
  std::string name;
  std::string address;
  std::string interface_name;
};

/// The team file, seen from one rover.
struct TeamConfig {
  uint32_t domain_id = 0;
  std::vector<TeamMember> robots;
  int self = 0;  ///< this rover's id (one of robots)
  /// The team protocol's options; sync.team holds every robot's id.
  TeamWorkerOptions worker{};

  /// This rover's entry.
  const TeamMember& Self() const;
  /// The other rovers' addresses (DDS unicast peers).
  std::vector<std::string> PeerAddresses() const;
  /// Cyclone DDS's XML for this rover: its interface, unicast to the peers.
  std::string DdsConfigXml() const;

  /// Reads the team file's root as rover `self_id`. Throws ConfigError
  /// naming file:line and key for a missing key, an id or name used twice,
  /// or a `self_id` that is not in the team.
  static TeamConfig Load(const ConfigNode& root, int self_id);
};

}  // namespace rover::mapd

#endif  // ROVER_FIRMWARE_MAPD_TEAM_CONFIG_H_
