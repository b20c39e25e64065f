#ifndef ROVER_FIRMWARE_MAPD_TEAM_EXCHANGE_H_
#define ROVER_FIRMWARE_MAPD_TEAM_EXCHANGE_H_

// mapd's side of the team: it shares this rover's graph factors with the
// other rovers (through the TeamWorker's thread), takes theirs in, checked,
// and logs every message both ways (rover_msgs/TeamMessage on
// /mapd/team/sent and /mapd/team/received). The log is what a restarted mapd
// starts from: its own messages get the same numbers again and the others'
// are held again, so the team resends only what it missed, and nothing
// arrives twice.
//
// A received constraint joins this rover's graph only if every robot it
// names is in the team and it is not one of this rover's own; anything else
// is refused, counted, and the reason kept for the summary.

#include <cstdint>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "core/link/link_endpoint.h"
#include "firmware/mapd/team_worker.h"
#include "mapping/slam/graph_log.h"
#include "mapping/team/team_message.h"
#include "mapping/team/team_submap.h"

namespace rover::mapd {

class SubmapArchive;

/// Another rover's finished submap, decoded and checked.
struct ReceivedSubmap {
  int robot = 0;
  mapping::TeamSubmap messages;
};

/// What arrived from the team since the last Take.
struct TeamArrivals {
  /// The other rovers' constraints, checked, in arrival order.
  std::vector<log::rover_msgs::GraphFactor> constraints;
  std::vector<mapping::MatchClaim> claims;
  std::vector<ReceivedSubmap> submaps;
};

/// Counters of the team exchange.
struct TeamExchangeStats {
  uint64_t constraints_shared = 0;    ///< this rover's factors handed to the team
  uint64_t constraints_received = 0;  ///< the others' factors added to this graph
  uint64_t constraints_refused = 0;   ///< received but refused (see last_refusal)
  uint64_t messages_resumed = 0;      ///< taken over from the previous mapd's log
  uint64_t submaps_shared = 0;
  uint64_t submap_bytes_shared = 0;  ///< compressed, as sent
  uint64_t submaps_not_shared = 0;   ///< could not be encoded (message printed)
  uint64_t submaps_received = 0;
  uint64_t submaps_refused = 0;  ///< did not decode (damage, checksum); see last_refusal
  uint64_t claims_shared = 0;
  uint64_t claims_received = 0;
  /// Bytes this rover sent on the link per second of wall time since the
  /// exchange started (the radio's view: summaries, resends and all).
  double link_bytes_per_s = 0.0;
  std::string last_refusal;
  TeamWorkerStats worker;
};

class TeamExchange {
 public:
  /// Starts the team thread on `endpoint` as robot `self`. `archive` (may be
  /// null) logs every message. `resumed` (may be null) is this mission's
  /// earlier mapd log: its team messages are logged again and handed to the
  /// protocol as what this rover already has. Throws std::invalid_argument
  /// for invalid options, an endpoint of another robot id, or a resumed log
  /// whose own messages are another robot's.
  TeamExchange(int self, std::unique_ptr<link::LinkEndpoint> endpoint,
               const TeamWorkerOptions& options, SubmapArchive* archive,
               const mapping::GraphLogContents* resumed);
  ~TeamExchange();
  TeamExchange(const TeamExchange&) = delete;
  TeamExchange& operator=(const TeamExchange&) = delete;

  /// Shares one factor of this rover's graph, as logged (priors stay home:
  /// each rover anchors its own map). `stamp_ns` is the log time.
  void Share(const log::rover_msgs::GraphFactor& msg, int64_t stamp_ns);
  /// Shares one of this rover's finished submaps (compressed, sent once).
  void ShareSubmap(const mapping::TeamSubmap& submap, int64_t stamp_ns);
  /// Announces that this rover matches the pair (a, b).
  void ShareClaim(const mapping::MatchClaim& claim, int64_t stamp_ns);
  /// What the other rovers sent since the last call, logged and checked.
  TeamArrivals Take(int64_t stamp_ns);
  /// This rover's latest global pose for the others.
  void SetHeartbeat(const mapping::TeamHeartbeat& heartbeat);

  TeamExchangeStats Stats() const;
  /// One line for mapd's summary.
  std::string Summary() const;
  /// Stops the team thread (idempotent).
  void Stop();

 private:
  void Log(std::string_view topic, int32_t origin, mapping::TeamStream stream, uint64_t seq,
           const std::vector<uint8_t>& bytes, int64_t stamp_ns);
  /// Counts nothing; keeps and prints the reason.
  void Refuse(const std::string& what, const std::string& why);
  /// Empty if `record` may join the graph, else why not.
  std::string Check(const mapping::GraphFactorRecord& record) const;

  const int self_;
  SubmapArchive* archive_;
  std::unique_ptr<TeamWorker> worker_;
  std::map<mapping::TeamStream, uint64_t> sent_;  ///< last number per stream
  std::set<int> team_;                            ///< the other robots' ids (empty: any)
  Time started_ = Time::Now();
  TeamExchangeStats stats_;
};

}  // namespace rover::mapd

#endif  // ROVER_FIRMWARE_MAPD_TEAM_EXCHANGE_H_
