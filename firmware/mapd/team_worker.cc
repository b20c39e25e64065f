#include "firmware/mapd/team_worker.h"

#include <chrono>
#include <stdexcept>
#include <utility>

namespace rover::mapd {

void TeamWorkerOptions::Validate() const {
  sync.Validate();
  if (tick <= Duration::Zero() || tick > Duration::Seconds(1)) {
    throw std::invalid_argument("TeamWorkerOptions.tick: expected 0 .. 1 s, found " +
                                std::to_string(tick.ToSeconds()) + " s");
  }
}

TeamWorker::TeamWorker(std::unique_ptr<link::LinkEndpoint> endpoint,
                       const TeamWorkerOptions& options, const TeamBacklog& backlog)
    : options_(options), endpoint_(std::move(endpoint)) {
  if (!endpoint_) throw std::invalid_argument("TeamWorker: no link endpoint");
  options_.Validate();
  self_ = endpoint_->self();
  sync_ = std::make_unique<link::TeamSync>(endpoint_.get(), options_.sync);
  for (const TeamRecord& r : backlog.own) {
    if (r.origin != self_) {
      throw std::invalid_argument("TeamWorker: backlog of own messages holds one of robot " +
                                  std::to_string(r.origin));
    }
    sync_->Publish(static_cast<uint8_t>(r.stream), r.bytes);
  }
  for (const TeamRecord& r : backlog.received) {
    if (r.origin == self_ || r.seq == 0) {
      throw std::invalid_argument("TeamWorker: backlog of received messages holds " +
                                  std::string(r.seq == 0 ? "message number 0" : "its own one"));
    }
    sync_->Restore(r.origin, static_cast<uint8_t>(r.stream), r.seq, r.bytes);
  }
  thread_ = std::thread([this] { Run(); });
}

TeamWorker::~TeamWorker() { Stop(); }

void TeamWorker::Stop() {
  {
    const std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void TeamWorker::PublishConstraint(const mapping::GraphFactorRecord& record) {
  std::vector<uint8_t> bytes = mapping::EncodeConstraint(record);
  const std::lock_guard lock(mutex_);
  outbox_.emplace_back(mapping::TeamStream::kConstraints, std::move(bytes));
}

void TeamWorker::PublishConstraint(const log::rover_msgs::GraphFactor& msg) {
  std::vector<uint8_t> bytes = mapping::EncodeConstraint(msg);
  const std::lock_guard lock(mutex_);
  outbox_.emplace_back(mapping::TeamStream::kConstraints, std::move(bytes));
}

void TeamWorker::PublishClaim(const mapping::MatchClaim& claim) {
  std::vector<uint8_t> bytes = mapping::EncodeMatchClaim(claim);
  const std::lock_guard lock(mutex_);
  outbox_.emplace_back(mapping::TeamStream::kMatchClaims, std::move(bytes));
}

void TeamWorker::PublishSubmap(std::vector<uint8_t> bytes) {
  const std::lock_guard lock(mutex_);
  outbox_.emplace_back(mapping::TeamStream::kSubmaps, std::move(bytes));
}

void TeamWorker::SetHeartbeat(const mapping::TeamHeartbeat& heartbeat) {
  std::vector<uint8_t> bytes = mapping::EncodeHeartbeat(heartbeat);
  const std::lock_guard lock(mutex_);
  heartbeat_ = std::move(bytes);
}

TeamInbox TeamWorker::Take() {
  const std::lock_guard lock(mutex_);
  TeamInbox out;
  std::swap(out, inbox_);
  return out;
}

TeamWorkerStats TeamWorker::Stats() const {
  const std::lock_guard lock(mutex_);
  return stats_;
}

// Decodes one delivered message into the inbox (called with the lock held).
void TeamWorker::Deliver(const link::TeamMessage& m) {
  TeamRecord record{m.origin, static_cast<mapping::TeamStream>(m.stream), m.seq, m.bytes};
  const std::string where = "message " + std::to_string(m.origin) + "/" + std::to_string(m.stream) +
                            "/" + std::to_string(m.seq) + ": ";
  try {
    switch (record.stream) {
      case mapping::TeamStream::kConstraints: {
        log::rover_msgs::GraphFactor msg = mapping::DecodeConstraintMessage(m.bytes);
        mapping::GraphFactorRecord f = mapping::FromMsg(msg);
        if (f.a.robot != static_cast<int>(m.origin)) {
          throw mapping::TeamMessageError("a constraint of robot " + std::to_string(f.a.robot) +
                                          " from robot " + std::to_string(m.origin));
        }
        inbox_.constraints.push_back(std::move(f));
        inbox_.constraint_messages.push_back(std::move(msg));
        break;
      }
      case mapping::TeamStream::kMatchClaims:
        inbox_.claims.push_back(mapping::DecodeMatchClaim(m.bytes));
        break;
      case mapping::TeamStream::kSubmaps:
        inbox_.submaps.push_back(record);
        break;
      default:
        throw mapping::TeamMessageError("stream " + std::to_string(m.stream) + " is not used");
    }
  } catch (const mapping::TeamMessageError& e) {
    ++stats_.undecodable;
    stats_.last_decode_error = where + e.what();
    return;
  }
  inbox_.records.push_back(std::move(record));
}

void TeamWorker::Run() {
  std::unique_lock lock(mutex_);
  while (!stop_) {
    auto outbox = std::move(outbox_);
    outbox_.clear();
    std::optional<std::vector<uint8_t>> heartbeat;
    heartbeat.swap(heartbeat_);
    lock.unlock();
    for (auto& [stream, bytes] : outbox) sync_->Publish(static_cast<uint8_t>(stream), bytes);
    if (heartbeat) sync_->SetHeartbeat(std::move(*heartbeat));
    sync_->Tick();
    std::vector<link::TeamMessage> delivered = sync_->TakeDelivered();
    std::vector<link::TeamPeer> peers = sync_->peers();
    lock.lock();
    for (const link::TeamMessage& m : delivered) Deliver(m);
    stats_.sync = sync_->stats();
    stats_.link = endpoint_->stats();
    for (const link::TeamPeer& p : peers) {
      if (p.heartbeat.empty() || heartbeat_bytes_[p.id] == p.heartbeat) continue;
      heartbeat_bytes_[p.id] = p.heartbeat;
      try {
        stats_.heartbeats[p.id] = mapping::DecodeHeartbeat(p.heartbeat);
      } catch (const mapping::TeamMessageError& e) {
        ++stats_.undecodable;
        stats_.last_decode_error = "heartbeat of robot " + std::to_string(p.id) + ": " + e.what();
      }
    }
    stats_.peers = std::move(peers);
    wake_.wait_for(lock, std::chrono::nanoseconds(options_.tick.nanoseconds()),
                   [this] { return stop_; });
  }
}

}  // namespace rover::mapd
