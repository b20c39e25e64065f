#ifndef ROVER_FIRMWARE_MAPD_TEAM_WORKER_H_
#define ROVER_FIRMWARE_MAPD_TEAM_WORKER_H_

// mapd's team thread: owns the team link (a LinkEndpoint, Cyclone DDS on a
// rover) and the team protocol (TeamSync) on it, so that a slow radio never
// holds up mapping. The main loop hands it what the team should know (this
// rover's constraints, match claims, submaps, its latest global pose) and
// takes what the other rovers sent: constraints decoded and checked (a
// message that does not decode is counted with the reason and dropped;
// nothing else is lost), claims, submaps and heartbeats.
//
// After a restart, mapd hands the constructor what its log says it had: its
// own messages in the order it first published them (they get the same
// numbers again) and those it had received (held again, not delivered
// again), so the team resends only what it missed.

#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "core/link/link_endpoint.h"
#include "core/link/team_sync.h"
#include "mapping/team/team_message.h"

namespace rover::mapd {

struct TeamWorkerOptions {
  link::TeamSyncOptions sync{};
  /// How often the thread reads the link and sends.
  Duration tick = Duration::Milliseconds(20);

  /// Throws std::invalid_argument naming the key.
  void Validate() const;
};

/// One message of the team as it travelled (for mapd's log, and for the
/// backlog after a restart).
struct TeamRecord {
  link::RobotId origin = 0;
  mapping::TeamStream stream = mapping::TeamStream::kConstraints;
  uint64_t seq = 0;
  std::vector<uint8_t> bytes;
};

/// What a restarted mapd had: its own messages in publishing order, and the
/// others' it had received.
struct TeamBacklog {
  std::vector<TeamRecord> own;
  std::vector<TeamRecord> received;
};

/// What arrived since the last Take.
struct TeamInbox {
  std::vector<TeamRecord> records;  ///< every message, as received (to log)
  std::vector<mapping::GraphFactorRecord> constraints;
  /// The same constraints as their senders logged them (same order).
  std::vector<log::rover_msgs::GraphFactor> constraint_messages;
  std::vector<mapping::MatchClaim> claims;
  std::vector<TeamRecord> submaps;
};

struct TeamWorkerStats {
  link::TeamSyncStats sync;
  link::LinkStats link;
  uint64_t undecodable = 0;       ///< messages that did not decode (dropped)
  std::string last_decode_error;  ///< why the latest one did not
  std::vector<link::TeamPeer> peers;
  std::map<link::RobotId, mapping::TeamHeartbeat> heartbeats;  ///< latest per peer
};

class TeamWorker {
 public:
  /// Starts the thread. Throws std::invalid_argument for invalid options or
  /// no endpoint.
  TeamWorker(std::unique_ptr<link::LinkEndpoint> endpoint, const TeamWorkerOptions& options,
             const TeamBacklog& backlog = {});
  ~TeamWorker();
  TeamWorker(const TeamWorker&) = delete;
  TeamWorker& operator=(const TeamWorker&) = delete;

  /// Queue for the team; never blocks on the link.
  void PublishConstraint(const mapping::GraphFactorRecord& record);
  /// A constraint as this rover logged it (the team gets the same bits).
  void PublishConstraint(const log::rover_msgs::GraphFactor& msg);
  void PublishClaim(const mapping::MatchClaim& claim);
  void PublishSubmap(std::vector<uint8_t> bytes);
  void SetHeartbeat(const mapping::TeamHeartbeat& heartbeat);

  /// What the other rovers sent since the last call.
  TeamInbox Take();
  TeamWorkerStats Stats() const;
  link::RobotId self() const { return self_; }

  /// Stops the thread (idempotent).
  void Stop();

 private:
  void Run();
  void Deliver(const link::TeamMessage& m);

  TeamWorkerOptions options_;
  link::RobotId self_;
  std::unique_ptr<link::LinkEndpoint> endpoint_;
  std::unique_ptr<link::TeamSync> sync_;  // used on the thread only (after start-up)

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::vector<std::pair<mapping::TeamStream, std::vector<uint8_t>>> outbox_;
  std::optional<std::vector<uint8_t>> heartbeat_;
  TeamInbox inbox_;
  TeamWorkerStats stats_;
  std::map<link::RobotId, std::vector<uint8_t>> heartbeat_bytes_;  // decoded last
  std::thread thread_;
};

}  // namespace rover::mapd

#endif  // ROVER_FIRMWARE_MAPD_TEAM_WORKER_H_
