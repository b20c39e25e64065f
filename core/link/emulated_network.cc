#include "core/link/emulated_network.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <string_view>

#include "core/link/option_error.h"

namespace rover::link {

void LinkConditions::Validate() const {
  constexpr std::string_view kName = "LinkConditions";
  if (delay < Duration::Zero())
    FailOption(kName, "delay", ">= 0", std::to_string(delay.ToSeconds()) + " s");
  if (jitter < Duration::Zero()) {
    FailOption(kName, "jitter", ">= 0", std::to_string(jitter.ToSeconds()) + " s");
  }
  if (!(loss >= 0.0 && loss <= 1.0)) FailOption(kName, "loss", "0..1", std::to_string(loss));
  if (!(std::isfinite(rate_bytes_per_s) && rate_bytes_per_s >= 0.0)) {
    FailOption(kName, "rate_bytes_per_s", ">= 0 (0: unlimited)", std::to_string(rate_bytes_per_s));
  }
  for (const Outage& o : outages) {
    if (!(o.end > o.start)) {
      FailOption(
          kName, "outages", "end after start",
          std::to_string(o.start.ToSeconds()) + " .. " + std::to_string(o.end.ToSeconds()) + " s");
    }
  }
}

class EmulatedNetwork::Endpoint final : public LinkEndpoint {
 public:
  Endpoint(EmulatedNetwork* network, RobotId id) : network_(network), id_(id) {}
  ~Endpoint() override { network_->endpoints_.erase(id_); }

  RobotId self() const override { return id_; }
  bool Send(RobotId to, std::span<const uint8_t> bytes) override {
    if (!network_->Send(id_, to, bytes)) {
      ++stats_.refused;
      return false;
    }
    ++stats_.sent;
    stats_.sent_bytes += bytes.size();
    return true;
  }
  std::optional<Datagram> Receive() override {
    if (inbox_.empty()) return std::nullopt;
    Datagram d = std::move(inbox_.front());
    inbox_.pop_front();
    ++stats_.received;
    stats_.received_bytes += d.bytes.size();
    return d;
  }
  Time Now() const override { return network_->now(); }
  LinkStats stats() const override { return stats_; }

  void Deliver(Datagram d) { inbox_.push_back(std::move(d)); }

 private:
  EmulatedNetwork* network_;
  RobotId id_;
  std::deque<Datagram> inbox_;
  LinkStats stats_;
};

EmulatedNetwork::EmulatedNetwork(uint64_t seed, Time start) : rng_(seed), now_(start) {}

EmulatedNetwork::~EmulatedNetwork() = default;

std::unique_ptr<LinkEndpoint> EmulatedNetwork::Join(RobotId id) {
  if (id == kAllRobots) {
    throw std::invalid_argument("EmulatedNetwork::Join: robot id " + std::to_string(id) +
                                " is the broadcast address");
  }
  if (endpoints_.count(id) != 0) {
    throw std::invalid_argument("EmulatedNetwork::Join: robot " + std::to_string(id) +
                                " has joined already");
  }
  auto endpoint = std::make_unique<Endpoint>(this, id);
  endpoints_[id] = endpoint.get();
  return endpoint;
}

void EmulatedNetwork::SetConditions(RobotId from, RobotId to, const LinkConditions& conditions) {
  conditions.Validate();
  DirectionOf(from, to).conditions = conditions;
}

void EmulatedNetwork::SetConditionsBothWays(RobotId a, RobotId b,
                                            const LinkConditions& conditions) {
  SetConditions(a, b, conditions);
  SetConditions(b, a, conditions);
}

EmulatedNetwork::Direction& EmulatedNetwork::DirectionOf(RobotId from, RobotId to) {
  auto [it, added] = directions_.try_emplace({from, to});
  if (added) it->second.free_at = now_;
  return it->second;
}

DirectionStats EmulatedNetwork::stats(RobotId from, RobotId to) const {
  const auto it = directions_.find({from, to});
  return it == directions_.end() ? DirectionStats{} : it->second.stats;
}

bool EmulatedNetwork::Send(RobotId from, RobotId to, std::span<const uint8_t> bytes) {
  if (bytes.size() > kMaxDatagramBytes || to == from) return false;
  if (to != kAllRobots) {
    SendOne(from, to, bytes);
    return true;
  }
  for (const auto& [id, endpoint] : endpoints_) {
    if (id != from) SendOne(from, id, bytes);
  }
  return true;
}

void EmulatedNetwork::SendOne(RobotId from, RobotId to, std::span<const uint8_t> bytes) {
  Direction& d = DirectionOf(from, to);
  const LinkConditions& c = d.conditions;
  ++d.stats.sent;
  for (const Outage& o : c.outages) {
    if (now_ >= o.start && now_ < o.end) {
      ++d.stats.dropped_outage;
      return;
    }
  }
  if (c.loss > 0.0 && std::uniform_real_distribution<double>(0.0, 1.0)(rng_) < c.loss) {
    ++d.stats.lost;
    return;
  }
  Time departure = now_;
  if (c.rate_bytes_per_s > 0.0) {
    const Time start = d.free_at > now_ ? d.free_at : now_;
    const double waiting_bytes = (start - now_).ToSeconds() * c.rate_bytes_per_s;
    if (waiting_bytes > static_cast<double>(c.queue_bytes)) {
      ++d.stats.dropped_queue;
      return;
    }
    departure =
        start + Duration::FromSeconds(static_cast<double>(bytes.size()) / c.rate_bytes_per_s);
    d.free_at = departure;
  }
  Duration extra = Duration::Zero();
  if (c.jitter > Duration::Zero()) {
    extra = Duration::Nanoseconds(
        std::uniform_int_distribution<int64_t>(0, c.jitter.nanoseconds() - 1)(rng_));
  }
  InFlight f;
  f.arrival = departure + c.delay + extra;
  f.order = order_++;
  f.datagram.from = from;
  f.datagram.to = to;
  f.datagram.bytes.assign(bytes.begin(), bytes.end());
  in_flight_.push(std::move(f));
}

void EmulatedNetwork::AdvanceTo(Time now) {
  if (now > now_) now_ = now;
  while (!in_flight_.empty() && in_flight_.top().arrival <= now_) {
    InFlight f = in_flight_.top();
    in_flight_.pop();
    Direction& d = DirectionOf(f.datagram.from, f.datagram.to);
    const auto it = endpoints_.find(f.datagram.to);
    if (it == endpoints_.end()) continue;  // the rover left the team
    ++d.stats.delivered;
    d.stats.delivered_bytes += f.datagram.bytes.size();
    f.datagram.received = f.arrival;
    it->second->Deliver(std::move(f.datagram));
  }
}

}  // namespace rover::link
