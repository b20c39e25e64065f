#ifndef ROVER_CORE_LINK_TEAM_SYNC_H_
#define ROVER_CORE_LINK_TEAM_SYNC_H_

// The team protocol: every rover ends up holding every message any rover of
// the team published, each delivered to the application once, over a link
// that delays, loses, duplicates and reorders datagrams and goes silent for
// minutes.
//
// Messages are numbered per origin rover and stream (1, 2, 3, ...), cut
// into fragments that fit a datagram, and checked end to end (CRC-32 of the
// whole message). Each rover broadcasts a summary of what it holds every
// summary_interval: per origin and stream, the highest number up to which
// it holds everything, the ranges it holds beyond that, and which fragments
// of unfinished messages it has. A rover that reads a peer's summary sends
// that peer what the summary lacks and it holds, whoever published it, so
// data also reaches a rover through a third one (store and forward) and a
// rover back from an outage or a reboot gets exactly what it missed.
//
// - Budget: everything a rover sends (summaries first, then data by stream
//   number, its own messages before others', oldest first) is paced by a
//   token bucket of budget_bytes_per_s.
// - Resending: a fragment goes again to a peer whose summaries still lack it
//   a round trip and a summary interval (and an eighth of a round trip for
//   jitter) after it was sent: by then a summary sent after its arrival has
//   come back. Round trips are measured by echoing summaries' send times, so
//   the peers' clocks need not agree. Urgent streams go out in several
//   copies (copies_by_stream). A peer not heard from for peer_silence gets
//   nothing but summaries until it is heard again.
// - Bad input: a datagram that is truncated, fails its CRC, has another
//   magic or version, comes from this rover's own id or from a rover not in
//   the team, or contradicts fragments already held, is refused and counted
//   with the reason; nothing already received is touched.
// - Restarts: the application publishes its own messages again in the same
//   order (the same numbers) and Restores what it had received (from its
//   log); restored messages are not delivered again.
//
// Not thread-safe: one thread calls everything (mapd's team thread).

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/link/link_endpoint.h"

namespace rover::link {

/// Streams are numbered 0 .. kMaxStreams - 1; a lower number goes first
/// when the budget is short.
inline constexpr uint8_t kMaxStreams = 8;

struct TeamSyncOptions {
  Duration summary_interval = Duration::Milliseconds(500);
  /// Everything this rover sends on the link, on average [bytes/s].
  double budget_bytes_per_s = 30000.0;
  /// Largest burst the budget allows [bytes].
  double burst_bytes = 12000.0;
  /// Shortest wait before a fragment is sent to the same peer again.
  Duration min_resend = Duration::Seconds(1);
  /// How many times a fragment goes out each time it is sent, by stream
  /// (streams past the end: once). Copies make a small, urgent stream arrive
  /// on the first try over a lossy link instead of a round trip later.
  std::vector<int> copies_by_stream = {2};
  /// Round trip assumed until one is measured.
  Duration initial_round_trip = Duration::Seconds(1);
  /// A peer not heard from for this long gets only summaries.
  Duration peer_silence = Duration::Seconds(10);
  /// Messages larger than this are refused (when published and received).
  std::size_t max_message_bytes = 8u << 20;
  /// The team's robot ids; datagrams from any other id are refused. Empty:
  /// any id but this rover's own.
  std::vector<RobotId> team;

  /// Throws std::invalid_argument "TeamSyncOptions.<key>: expected ..., found ...".
  void Validate() const;
};

/// A message as the application sees it.
struct TeamMessage {
  RobotId origin = 0;
  uint8_t stream = 0;
  uint64_t seq = 0;  ///< from 1, per origin and stream
  std::vector<uint8_t> bytes;
  Time completed;  ///< when its last fragment arrived here
};

/// What this rover knows of a peer.
struct TeamPeer {
  RobotId id = 0;
  Time last_heard;
  Duration round_trip = Duration::Zero();  ///< smoothed; zero until measured
  std::vector<uint8_t> heartbeat;          ///< the peer's latest SetHeartbeat
  bool silent = false;                     ///< not heard for peer_silence
};

struct TeamSyncStats {
  uint64_t published = 0;
  uint64_t delivered = 0;  ///< messages from others completed here
  uint64_t duplicate_fragments = 0;
  uint64_t fragments_sent = 0;
  uint64_t fragments_resent = 0;
  uint64_t summaries_sent = 0;
  uint64_t summaries_received = 0;
  uint64_t bytes_sent = 0;
  uint64_t refused_datagrams = 0;
  uint64_t checksum_failures = 0;  ///< reassembled messages whose CRC failed
  std::string last_refusal;        ///< why the latest refused datagram was refused
};

class TeamSync {
 public:
  /// `endpoint` must outlive this. Throws std::invalid_argument for invalid
  /// options.
  TeamSync(LinkEndpoint* endpoint, const TeamSyncOptions& options);
  ~TeamSync();
  TeamSync(const TeamSync&) = delete;
  TeamSync& operator=(const TeamSync&) = delete;

  /// Adds this rover's next message on `stream`; returns its number. Throws
  /// std::invalid_argument for a stream >= kMaxStreams or a message larger
  /// than max_message_bytes.
  uint64_t Publish(uint8_t stream, std::vector<uint8_t> bytes);

  /// Puts back a message received before a restart, without delivering it
  /// again. Ignored if already held.
  void Restore(RobotId origin, uint8_t stream, uint64_t seq, std::vector<uint8_t> bytes);

  /// Data carried in every summary (e.g. the latest global pose); peers see
  /// it in TeamPeer::heartbeat. At most 256 bytes.
  void SetHeartbeat(std::vector<uint8_t> bytes);

  /// Reads what arrived, sends the summary when due and what peers lack,
  /// within the budget. Call every few tens of milliseconds.
  void Tick();

  /// Messages from other rovers completed since the last call, each once,
  /// in the order they completed.
  std::vector<TeamMessage> TakeDelivered();

  /// True if the message is held here (complete).
  bool Has(RobotId origin, uint8_t stream, uint64_t seq) const;
  /// Messages held here from `origin` on `stream` (1..n complete).
  uint64_t ContiguousCount(RobotId origin, uint8_t stream) const;

  std::vector<TeamPeer> peers() const;
  const TeamSyncStats& stats() const { return stats_; }
  RobotId self() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  TeamSyncStats stats_;
};

}  // namespace rover::link

#endif  // ROVER_CORE_LINK_TEAM_SYNC_H_
