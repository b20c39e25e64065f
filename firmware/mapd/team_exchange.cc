#include "firmware/mapd/team_exchange.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <utility>

#include "core/log/msgs/message_traits.h"
#include "firmware/mapd/submap_archive.h"
#include "mapping/team/team_message.h"
#include "mapping/team/team_submap.h"

namespace rover::mapd {
namespace {

TeamRecord RecordOf(const log::rover_msgs::TeamMessage& m) {
  return {static_cast<link::RobotId>(m.origin), static_cast<mapping::TeamStream>(m.stream), m.seq,
          m.data};
}

// The backlog a restarted mapd hands the protocol: what its log says it had.
TeamBacklog BacklogOf(int self, const mapping::GraphLogContents* resumed) {
  TeamBacklog backlog;
  if (resumed == nullptr) return backlog;
  for (const log::rover_msgs::TeamMessage& m : resumed->team_sent) {
    if (m.origin != self) {
      throw std::invalid_argument("mapd team: the previous log's sent messages are robot " +
                                  std::to_string(m.origin) + "'s, this rover is robot " +
                                  std::to_string(self));
    }
    backlog.own.push_back(RecordOf(m));
  }
  for (const log::rover_msgs::TeamMessage& m : resumed->team_received) {
    backlog.received.push_back(RecordOf(m));
  }
  return backlog;
}

}  // namespace

TeamExchange::TeamExchange(int self, std::unique_ptr<link::LinkEndpoint> endpoint,
                           const TeamWorkerOptions& options, SubmapArchive* archive,
                           const mapping::GraphLogContents* resumed)
    : self_(self), archive_(archive) {
  if (!endpoint) throw std::invalid_argument("mapd team: no link endpoint");
  if (endpoint->self() != static_cast<link::RobotId>(self)) {
    throw std::invalid_argument("mapd team: the link endpoint is robot " +
                                std::to_string(endpoint->self()) + "'s, this rover is robot " +
                                std::to_string(self));
  }
  TeamBacklog backlog = BacklogOf(self, resumed);
  for (const TeamRecord& r : backlog.own) {
    uint64_t& last = sent_[r.stream];
    last = std::max(last, r.seq);
    Log(mapping::kTeamSentTopic, self, r.stream, r.seq, r.bytes, 0);
  }
  for (const TeamRecord& r : backlog.received) {
    Log(mapping::kTeamReceivedTopic, static_cast<int32_t>(r.origin), r.stream, r.seq, r.bytes, 0);
  }
  stats_.messages_resumed = backlog.own.size() + backlog.received.size();
  worker_ = std::make_unique<TeamWorker>(std::move(endpoint), options, backlog);
  for (const link::RobotId id : options.sync.team) {
    if (static_cast<int>(id) != self) team_.insert(static_cast<int>(id));
  }
}

TeamExchange::~TeamExchange() { Stop(); }

void TeamExchange::Stop() { worker_->Stop(); }

void TeamExchange::Log(std::string_view topic, int32_t origin, mapping::TeamStream stream,
                       uint64_t seq, const std::vector<uint8_t>& bytes, int64_t stamp_ns) {
  if (archive_ == nullptr) return;
  log::rover_msgs::TeamMessage m;
  m.header.stamp = log::ToRosTime(Time::FromNanoseconds(stamp_ns));
  m.header.frame_id = log::FrameId::Truncated("team");
  m.origin = origin;
  m.stream = static_cast<uint8_t>(stream);
  m.seq = seq;
  m.data = bytes;
  archive_->LogTeamMessage(topic, m);
}

void TeamExchange::Share(const log::rover_msgs::GraphFactor& msg, int64_t stamp_ns) {
  if (msg.kind == log::rover_msgs::GraphFactor::kPrior) return;
  worker_->PublishConstraint(msg);
  const uint64_t seq = ++sent_[mapping::TeamStream::kConstraints];
  Log(mapping::kTeamSentTopic, self_, mapping::TeamStream::kConstraints, seq,
      mapping::EncodeConstraint(msg), stamp_ns);
  ++stats_.constraints_shared;
}

std::string TeamExchange::Check(const mapping::GraphFactorRecord& record) const {
  const auto known = [this](const mapping::GraphKey& key) {
    return key.type == mapping::GraphKey::Type::kLandmark || team_.empty() ||
           team_.count(key.robot) > 0 || key.robot == self_;
  };
  if (record.kind == mapping::FactorKind::kPrior) {
    return "a prior (each rover anchors only its own map)";
  }
  if (record.a.robot == self_) return "it is this rover's own (" + record.a.ToString() + ")";
  for (const std::optional<mapping::GraphKey>& key : {std::optional(record.a), record.b}) {
    if (key && !known(*key)) {
      return "it names " + key->ToString() + " of robot " + std::to_string(key->robot) +
             ", which is not in the team";
    }
  }
  return {};
}

void TeamExchange::ShareSubmap(const mapping::TeamSubmap& submap, int64_t stamp_ns) {
  std::vector<uint8_t> bytes;
  try {
    bytes = mapping::EncodeSubmap(submap);
  } catch (const std::exception& e) {
    // The team goes without this submap; mapping goes on.
    ++stats_.submaps_not_shared;
    std::fprintf(stderr, "mapd: team: submap %u not shared: %s\n", submap.info.frame_id, e.what());
    return;
  }
  const uint64_t seq = ++sent_[mapping::TeamStream::kSubmaps];
  Log(mapping::kTeamSentTopic, self_, mapping::TeamStream::kSubmaps, seq, bytes, stamp_ns);
  ++stats_.submaps_shared;
  stats_.submap_bytes_shared += bytes.size();
  worker_->PublishSubmap(std::move(bytes));
}

void TeamExchange::ShareClaim(const mapping::MatchClaim& claim, int64_t stamp_ns) {
  worker_->PublishClaim(claim);
  const uint64_t seq = ++sent_[mapping::TeamStream::kMatchClaims];
  Log(mapping::kTeamSentTopic, self_, mapping::TeamStream::kMatchClaims, seq,
      mapping::EncodeMatchClaim(claim), stamp_ns);
  ++stats_.claims_shared;
}

void TeamExchange::Refuse(const std::string& what, const std::string& why) {
  stats_.last_refusal = what + " refused: " + why;
  std::fprintf(stderr, "mapd: team: %s\n", stats_.last_refusal.c_str());
}

TeamArrivals TeamExchange::Take(int64_t stamp_ns) {
  TeamInbox inbox = worker_->Take();
  for (const TeamRecord& r : inbox.records) {
    Log(mapping::kTeamReceivedTopic, static_cast<int32_t>(r.origin), r.stream, r.seq, r.bytes,
        stamp_ns);
  }
  TeamArrivals out;
  for (std::size_t k = 0; k < inbox.constraints.size(); ++k) {
    const std::string refusal = Check(inbox.constraints[k]);
    if (!refusal.empty()) {
      ++stats_.constraints_refused;
      Refuse("constraint " + inbox.constraints[k].Describe() + " (id " +
                 std::to_string(inbox.constraints[k].id) + ")",
             refusal);
      continue;
    }
    ++stats_.constraints_received;
    out.constraints.push_back(std::move(inbox.constraint_messages[k]));
  }
  for (const mapping::MatchClaim& claim : inbox.claims) {
    ++stats_.claims_received;
    out.claims.push_back(claim);
  }
  for (const TeamRecord& r : inbox.submaps) {
    const std::string what =
        "submap message " + std::to_string(r.seq) + " of robot " + std::to_string(r.origin);
    if (!team_.empty() && team_.count(static_cast<int>(r.origin)) == 0) {
      ++stats_.submaps_refused;
      Refuse(what, "that robot is not in the team");
      continue;
    }
    try {
      out.submaps.push_back({static_cast<int>(r.origin), mapping::DecodeSubmap(r.bytes)});
      ++stats_.submaps_received;
    } catch (const mapping::TeamMessageError& e) {
      ++stats_.submaps_refused;
      Refuse(what, e.what());
    }
  }
  return out;
}

void TeamExchange::SetHeartbeat(const mapping::TeamHeartbeat& heartbeat) {
  worker_->SetHeartbeat(heartbeat);
}

TeamExchangeStats TeamExchange::Stats() const {
  TeamExchangeStats s = stats_;
  s.worker = worker_->Stats();
  const double wall_s = (Time::Now() - started_).ToSeconds();
  if (wall_s > 0.0) s.link_bytes_per_s = static_cast<double>(s.worker.link.sent_bytes) / wall_s;
  return s;
}

std::string TeamExchange::Summary() const {
  const TeamExchangeStats s = Stats();
  char text[400];
  std::snprintf(
      text, sizeof(text),
      "  team (robot %d): %llu constraints shared, %llu received, %llu refused; %zu "
      "peers; link %llu bytes sent (%.0f B/s), %llu received; %llu messages undecodable; %llu "
      "taken over from the previous log\n",
      self_, static_cast<unsigned long long>(s.constraints_shared),
      static_cast<unsigned long long>(s.constraints_received),
      static_cast<unsigned long long>(s.constraints_refused), s.worker.peers.size(),
      static_cast<unsigned long long>(s.worker.link.sent_bytes), s.link_bytes_per_s,
      static_cast<unsigned long long>(s.worker.link.received_bytes),
      static_cast<unsigned long long>(s.worker.undecodable),
      static_cast<unsigned long long>(s.messages_resumed));
  std::string out = text;
  std::snprintf(text, sizeof(text),
                "    submaps: %llu shared (%.1f KB compressed), %llu received, %llu refused; "
                "match claims: %llu shared, %llu received\n",
                static_cast<unsigned long long>(s.submaps_shared),
                static_cast<double>(s.submap_bytes_shared) / 1e3,
                static_cast<unsigned long long>(s.submaps_received),
                static_cast<unsigned long long>(s.submaps_refused),
                static_cast<unsigned long long>(s.claims_shared),
                static_cast<unsigned long long>(s.claims_received));
  out += text;
  if (!s.last_refusal.empty()) out += "    last refused: " + s.last_refusal + "\n";
  if (!s.worker.last_decode_error.empty()) {
    out += "    last undecodable: " + s.worker.last_decode_error + "\n";
  }
  return out;
}

}  // namespace rover::mapd
