#include "core/link/team_sync.h"

#include <algorithm>
#include <cmath>
#include <compare>
#include <deque>
#include <stdexcept>
#include <string_view>
#include <utility>

#include "core/link/option_error.h"
#include "core/link/wire.h"

namespace rover::link {
namespace {

constexpr uint32_t kMagic = 0x4C545652;  // "RVTL" little-endian
constexpr uint8_t kVersion = 1;
constexpr uint8_t kSummaryKind = 1;
constexpr uint8_t kFragmentKind = 2;
constexpr std::size_t kHeaderBytes = 12;  // magic, version, kind, reserved, sender
constexpr std::size_t kCrcBytes = 4;
constexpr std::size_t kFragmentHeaderBytes = 25;  // origin, stream, seq, size, crc, index, count
constexpr std::size_t kFragmentPayloadBytes =
    kMaxDatagramBytes - kHeaderBytes - kFragmentHeaderBytes - kCrcBytes;
constexpr std::size_t kMaxHeartbeatBytes = 256;
// Ranges beyond the contiguous count a summary lists per stream; a peer
// resends what falls outside them, which costs bytes, never correctness.
constexpr std::size_t kMaxRangesPerStream = 8;
// Round-trip samples outside this are a peer's clock jumping, not the link.
constexpr Duration kMaxRoundTrip = Duration::Seconds(120);

struct Key {
  RobotId origin = 0;
  uint8_t stream = 0;
  auto operator<=>(const Key&) const = default;
};

struct Message {
  std::shared_ptr<const std::vector<uint8_t>> bytes;
  uint32_t crc = 0;
  uint16_t fragments = 0;
};

struct Partial {
  uint32_t total_bytes = 0;
  uint32_t crc = 0;
  uint16_t count = 0;
  uint16_t received = 0;
  std::vector<bool> have;
  std::vector<uint8_t> buffer;
};

struct Stream {
  std::map<uint64_t, Message> complete;
  uint64_t contiguous = 0;  // 1..contiguous are all complete
  std::map<uint64_t, Partial> partial;
};

// What a peer's latest summary says it holds of one stream.
struct Holdings {
  uint64_t contiguous = 0;
  std::vector<std::pair<uint64_t, uint64_t>> ranges;  // [first, last]
  std::map<uint64_t, std::vector<bool>> partial;

  bool Holds(uint64_t seq) const {
    if (seq <= contiguous) return true;
    for (const auto& [first, last] : ranges) {
      if (seq >= first && seq <= last) return true;
    }
    return false;
  }
  bool HoldsFragment(uint64_t seq, uint16_t index) const {
    const auto it = partial.find(seq);
    return it != partial.end() && index < it->second.size() && it->second[index];
  }
};

struct Peer {
  bool heard = false;
  Time last_heard;
  std::map<Key, Holdings> holdings;
  std::vector<uint8_t> heartbeat;
  Duration round_trip = Duration::Zero();
  bool round_trip_measured = false;
  // For the echo in our summaries: the peer's latest summary's send time
  // (its clock) and when it arrived (ours).
  int64_t echo_sent_at_ns = 0;
  Time echo_received;
  bool has_echo = false;
  // When each fragment last went to this peer: [key][seq][index].
  std::map<Key, std::map<uint64_t, std::vector<Time>>> sent;
};

uint16_t FragmentCount(std::size_t bytes) {
  return static_cast<uint16_t>(
      std::max<std::size_t>(1, (bytes + kFragmentPayloadBytes - 1) / kFragmentPayloadBytes));
}

// A whole message as the store holds it.
Message MakeMessage(std::vector<uint8_t> bytes) {
  Message m;
  m.crc = wire::Crc32(bytes);
  m.fragments = FragmentCount(bytes.size());
  m.bytes = std::make_shared<const std::vector<uint8_t>>(std::move(bytes));
  return m;
}

void WriteHeader(wire::Writer* w, uint8_t kind, RobotId sender) {
  w->U32(kMagic);
  w->U8(kVersion);
  w->U8(kind);
  w->U16(0);
  w->U32(sender);
}

void SealDatagram(std::vector<uint8_t>* d) {
  const uint32_t crc = wire::Crc32(*d);
  wire::Writer(d).U32(crc);
}

}  // namespace

void TeamSyncOptions::Validate() const {
  constexpr std::string_view kName = "TeamSyncOptions";
  if (summary_interval <= Duration::Zero()) {
    FailOption(kName, "summary_interval", "> 0",
               std::to_string(summary_interval.ToSeconds()) + " s");
  }
  if (!(std::isfinite(budget_bytes_per_s) && budget_bytes_per_s >= 500.0)) {
    FailOption(kName, "budget_bytes_per_s", ">= 500 (summaries alone need a few hundred)",
               std::to_string(budget_bytes_per_s));
  }
  if (!(std::isfinite(burst_bytes) && burst_bytes >= static_cast<double>(kMaxDatagramBytes))) {
    FailOption(kName, "burst_bytes", ">= " + std::to_string(kMaxDatagramBytes) + " (one datagram)",
               std::to_string(burst_bytes));
  }
  if (min_resend <= Duration::Zero()) {
    FailOption(kName, "min_resend", "> 0", std::to_string(min_resend.ToSeconds()) + " s");
  }
  if (initial_round_trip <= Duration::Zero()) {
    FailOption(kName, "initial_round_trip", "> 0",
               std::to_string(initial_round_trip.ToSeconds()) + " s");
  }
  if (peer_silence <= summary_interval) {
    FailOption(kName, "peer_silence", "longer than summary_interval",
               std::to_string(peer_silence.ToSeconds()) + " s");
  }
  if (copies_by_stream.size() > kMaxStreams) {
    FailOption(kName, "copies_by_stream", "at most " + std::to_string(kMaxStreams) + " entries",
               std::to_string(copies_by_stream.size()));
  }
  for (const int copies : copies_by_stream) {
    if (copies < 1 || copies > 4)
      FailOption(kName, "copies_by_stream", "1..4 copies", std::to_string(copies));
  }
  const std::size_t max_fragments = UINT16_MAX;
  if (max_message_bytes == 0 || max_message_bytes > max_fragments * kFragmentPayloadBytes) {
    FailOption(kName, "max_message_bytes",
               "1.." + std::to_string(max_fragments * kFragmentPayloadBytes),
               std::to_string(max_message_bytes));
  }
}

struct TeamSync::Impl {
  Impl(LinkEndpoint* e, const TeamSyncOptions& o, TeamSyncStats* s)
      : endpoint(e), options(o), stats(s), tokens(o.burst_bytes) {}

  LinkEndpoint* endpoint;
  TeamSyncOptions options;
  TeamSyncStats* stats;
  std::map<Key, Stream> store;
  std::map<RobotId, Peer> peers;
  std::deque<TeamMessage> delivered;
  std::vector<uint8_t> heartbeat;
  double tokens;
  std::optional<Time> last_refill;
  std::optional<Time> last_summary;

  void Refuse(const std::string& why, RobotId from) {
    ++stats->refused_datagrams;
    stats->last_refusal = "datagram from robot " + std::to_string(from) + ": " + why;
  }

  bool InTeam(RobotId id) const {
    return options.team.empty() ||
           std::find(options.team.begin(), options.team.end(), id) != options.team.end();
  }

  static void Complete(Stream* st, uint64_t seq, Message m) {
    st->complete[seq] = std::move(m);
    while (st->complete.count(st->contiguous + 1) != 0) ++st->contiguous;
  }

  Duration ResendAfter(const Peer& p) const {
    const Duration rtt = p.round_trip_measured ? p.round_trip : options.initial_round_trip;
    const Duration jitter = std::max(Duration::Milliseconds(100), rtt / 8);
    return std::max(options.min_resend, rtt + options.summary_interval + jitter);
  }

  // ---- receiving ----

  void Handle(const Datagram& d, Time now) {
    if (d.bytes.size() < kHeaderBytes + kCrcBytes) {
      Refuse("truncated (" + std::to_string(d.bytes.size()) + " bytes)", d.from);
      return;
    }
    const std::span<const uint8_t> all(d.bytes);
    const std::span<const uint8_t> body = all.first(all.size() - kCrcBytes);
    wire::Reader crc_reader(all.last(kCrcBytes));
    if (crc_reader.U32() != wire::Crc32(body)) {
      Refuse("CRC mismatch", d.from);
      return;
    }
    wire::Reader r(body);
    const uint32_t magic = r.U32();
    const uint8_t version = r.U8();
    const uint8_t kind = r.U8();
    r.U16();
    const RobotId sender = r.U32();
    if (magic != kMagic) {
      Refuse("not a team-link datagram (magic " + std::to_string(magic) + ")", d.from);
    } else if (version != kVersion) {
      Refuse(
          "protocol version " + std::to_string(version) + ", expected " + std::to_string(kVersion),
          sender);
    } else if (sender == endpoint->self()) {
      Refuse("carries this rover's own id " + std::to_string(sender) +
                 " (a robot id used twice in the team?)",
             sender);
    } else if (!InTeam(sender)) {
      Refuse("robot " + std::to_string(sender) + " is not in the team", sender);
    } else if (kind == kSummaryKind) {
      HandleSummary(sender, &r, now);
    } else if (kind == kFragmentKind) {
      HandleFragment(sender, &r, now);
    } else {
      Refuse("unknown kind " + std::to_string(kind), sender);
    }
  }

  void HandleSummary(RobotId sender, wire::Reader* r, Time now) {
    const int64_t sent_at_ns = r->I64();
    const uint16_t heartbeat_bytes = r->U16();
    const std::span<const uint8_t> beat = r->Bytes(heartbeat_bytes);
    const uint8_t echoes = r->U8();
    std::optional<Duration> rtt_sample;
    for (uint8_t i = 0; i < echoes && !r->failed(); ++i) {
      const RobotId to = r->U32();
      const int64_t echoed_ns = r->I64();
      const int64_t hold_ns = r->I64();
      if (to == endpoint->self()) {
        rtt_sample = (now - Time::FromNanoseconds(echoed_ns)) - Duration::Nanoseconds(hold_ns);
      }
    }
    std::map<Key, Holdings> listed;
    const uint16_t entries = r->U16();
    for (uint16_t i = 0; i < entries && !r->failed(); ++i) {
      Key key;
      key.origin = r->U32();
      key.stream = r->U8();
      Holdings h;
      h.contiguous = r->U64();
      const uint8_t ranges = r->U8();
      for (uint8_t k = 0; k < ranges && !r->failed(); ++k) {
        const uint64_t first = r->U64();
        const uint64_t last = r->U64();
        h.ranges.emplace_back(first, last);
      }
      const uint8_t partials = r->U8();
      for (uint8_t k = 0; k < partials && !r->failed(); ++k) {
        const uint64_t seq = r->U64();
        const uint16_t count = r->U16();
        const std::span<const uint8_t> bits = r->Bytes((count + 7u) / 8u);
        std::vector<bool> have(count);
        for (uint16_t b = 0; b < count && !r->failed(); ++b) {
          have[b] = ((static_cast<unsigned>(bits[b / 8u]) >> (b % 8u)) & 1u) != 0;
        }
        h.partial[seq] = std::move(have);
      }
      listed[key] = std::move(h);
    }
    if (r->failed() || r->remaining() != 0) {
      Refuse("malformed summary", sender);
      return;
    }
    ++stats->summaries_received;
    Peer& p = peers[sender];
    p.heard = true;
    p.last_heard = now;
    p.heartbeat.assign(beat.begin(), beat.end());
    p.echo_sent_at_ns = sent_at_ns;
    p.echo_received = now;
    p.has_echo = true;
    if (rtt_sample && *rtt_sample >= Duration::Zero() && *rtt_sample <= kMaxRoundTrip) {
      p.round_trip = p.round_trip_measured ? (p.round_trip * 7 + *rtt_sample) / 8 : *rtt_sample;
      p.round_trip_measured = true;
    }
    for (auto& [key, h] : listed) {
      auto sent = p.sent.find(key);
      if (sent != p.sent.end()) {
        for (auto it = sent->second.begin(); it != sent->second.end();) {
          it = h.Holds(it->first) ? sent->second.erase(it) : std::next(it);
        }
      }
      p.holdings[key] = std::move(h);
    }
  }

  struct Fragment {
    Key key;
    uint64_t seq = 0;
    uint32_t total = 0;
    uint32_t crc = 0;
    uint16_t index = 0;
    uint16_t count = 0;
    std::span<const uint8_t> data;
    std::size_t offset = 0;  // of data in the message
    std::string what;        // "fragment i of message o/s/n", for refusals
  };

  // Reads a fragment and checks it against itself and the team; refuses
  // (and returns nothing) what does not hold together.
  std::optional<Fragment> ParseFragment(RobotId sender, wire::Reader* r) {
    Fragment f;
    f.key.origin = r->U32();
    f.key.stream = r->U8();
    f.seq = r->U64();
    f.total = r->U32();
    f.crc = r->U32();
    f.index = r->U16();
    f.count = r->U16();
    const std::size_t payload = r->remaining();
    f.data = r->Bytes(payload);
    f.what = "fragment " + std::to_string(f.index) + " of message " + std::to_string(f.key.origin) +
             "/" + std::to_string(f.key.stream) + "/" + std::to_string(f.seq);
    f.offset = std::size_t{f.index} * kFragmentPayloadBytes;
    const std::size_t expected =
        std::min(kFragmentPayloadBytes, f.total - std::min<std::size_t>(f.total, f.offset));
    std::string why;
    if (r->failed()) {
      why = "truncated";
    } else if (f.key.stream >= kMaxStreams) {
      why = "stream out of range";
    } else if (f.seq == 0) {
      why = "message number 0";
    } else if (f.total > options.max_message_bytes) {
      why = std::to_string(f.total) + " bytes, more than max_message_bytes";
    } else if (f.count != FragmentCount(f.total) || f.index >= f.count) {
      why = "fragment count " + std::to_string(f.count) + " does not fit " +
            std::to_string(f.total) + " bytes";
    } else if (payload != expected) {
      why = std::to_string(payload) + " payload bytes, expected " + std::to_string(expected);
    } else if (f.key.origin == endpoint->self()) {
      why = "origin " + std::to_string(f.key.origin) + " is this rover";
    } else if (!InTeam(f.key.origin)) {
      why = "origin " + std::to_string(f.key.origin) + " is not in the team";
    }
    if (!why.empty()) {
      Refuse(f.what + ": " + why, sender);
      return std::nullopt;
    }
    return f;
  }

  void HandleFragment(RobotId sender, wire::Reader* r, Time now) {
    const std::optional<Fragment> f = ParseFragment(sender, r);
    if (!f) return;
    Stream& st = store[f->key];
    const auto held = st.complete.find(f->seq);
    if (held != st.complete.end()) {
      if (held->second.crc != f->crc) {
        // The same number with other contents: two rovers send under one id.
        Refuse(f->what + ": differs from the message held under that number (robot " +
                   std::to_string(f->key.origin) + "'s id used by two rovers?)",
               sender);
        return;
      }
      ++stats->duplicate_fragments;
      return;
    }
    auto [it, added] = st.partial.try_emplace(f->seq);
    Partial& part = it->second;
    if (added) {
      part.total_bytes = f->total;
      part.crc = f->crc;
      part.count = f->count;
      part.have.assign(f->count, false);
      part.buffer.assign(f->total, 0);
    } else if (part.total_bytes != f->total || part.crc != f->crc || part.count != f->count) {
      Refuse(f->what + ": contradicts the fragments already held (size or CRC differ)", sender);
      return;
    }
    if (part.have[f->index]) {
      ++stats->duplicate_fragments;
      return;
    }
    std::copy(f->data.begin(), f->data.end(),
              part.buffer.begin() + static_cast<std::ptrdiff_t>(f->offset));
    part.have[f->index] = true;
    if (++part.received == part.count) Finish(f->key, f->seq, &st, now);
  }

  // The last fragment of message `seq` arrived: checks the whole message's
  // CRC and delivers it, or drops it (its fragments are asked for again).
  void Finish(const Key& key, uint64_t seq, Stream* st, Time now) {
    const auto it = st->partial.find(seq);
    Partial& part = it->second;
    if (wire::Crc32(part.buffer) != part.crc) {
      ++stats->checksum_failures;
      stats->last_refusal = "message " + std::to_string(key.origin) + "/" +
                            std::to_string(key.stream) + "/" + std::to_string(seq) +
                            ": CRC of the reassembled message does not match; dropped";
      st->partial.erase(it);
      return;
    }
    Message m;
    m.crc = part.crc;
    m.fragments = part.count;
    auto bytes = std::make_shared<std::vector<uint8_t>>(std::move(part.buffer));
    m.bytes = bytes;
    st->partial.erase(it);
    Complete(st, seq, m);
    ++stats->delivered;
    delivered.push_back({key.origin, key.stream, seq, *bytes, now});
  }

  // ---- sending ----

  void Refill(Time now) {
    if (last_refill) {
      tokens = std::min(options.burst_bytes,
                        tokens + (now - *last_refill).ToSeconds() * options.budget_bytes_per_s);
    }
    last_refill = now;
  }

  bool Spend(std::size_t bytes) {
    if (tokens < static_cast<double>(bytes)) return false;
    tokens -= static_cast<double>(bytes);
    return true;
  }

  void Emit(RobotId to, const std::vector<uint8_t>& datagram) {
    if (endpoint->Send(to, datagram)) stats->bytes_sent += datagram.size();
  }

  // The holdings part of a summary for one stream.
  static void WriteHoldings(const Key& key, const Stream& st, std::size_t room,
                            std::vector<uint8_t>* out) {
    wire::Writer w(out);
    w.U32(key.origin);
    w.U8(key.stream);
    w.U64(st.contiguous);
    std::vector<std::pair<uint64_t, uint64_t>> ranges;
    for (auto it = st.complete.upper_bound(st.contiguous); it != st.complete.end(); ++it) {
      if (!ranges.empty() && ranges.back().second + 1 == it->first) {
        ranges.back().second = it->first;
      } else if (ranges.size() < kMaxRangesPerStream) {
        ranges.emplace_back(it->first, it->first);
      } else {
        break;
      }
    }
    w.U8(static_cast<uint8_t>(ranges.size()));
    for (const auto& [first, last] : ranges) {
      w.U64(first);
      w.U64(last);
    }
    const std::size_t partial_count_at = out->size();
    w.U8(0);
    uint8_t partials = 0;
    for (const auto& [seq, part] : st.partial) {
      const std::size_t need = 8 + 2 + (part.count + 7u) / 8u;
      if (out->size() + need > room || partials == UINT8_MAX) break;
      w.U64(seq);
      w.U16(part.count);
      std::vector<uint8_t> bits((part.count + 7u) / 8u, 0);
      for (uint16_t b = 0; b < part.count; ++b) {
        if (part.have[b]) bits[b / 8u] = static_cast<uint8_t>(bits[b / 8u] | (1u << (b % 8u)));
      }
      w.Bytes(bits);
      ++partials;
    }
    (*out)[partial_count_at] = partials;
  }

  std::vector<uint8_t> SummaryStart(Time now) const {
    std::vector<uint8_t> d;
    wire::Writer w(&d);
    WriteHeader(&w, kSummaryKind, endpoint->self());
    w.I64(now.nanoseconds());
    w.U16(static_cast<uint16_t>(heartbeat.size()));
    w.Bytes(heartbeat);
    uint8_t echoes = 0;
    for (const auto& [id, p] : peers) echoes = static_cast<uint8_t>(echoes + (p.has_echo ? 1 : 0));
    w.U8(echoes);
    for (const auto& [id, p] : peers) {
      if (!p.has_echo) continue;
      w.U32(id);
      w.I64(p.echo_sent_at_ns);
      w.I64((now - p.echo_received).nanoseconds());
    }
    return d;
  }

  // One or more summary datagrams, each listing whole streams.
  void SendSummaries(Time now) {
    constexpr std::size_t kMinEntryBytes = 4 + 1 + 8 + 1 + 16 * kMaxRangesPerStream + 1;
    std::vector<std::vector<uint8_t>> datagrams;
    std::vector<uint8_t> d = SummaryStart(now);
    std::size_t count_at = d.size();
    wire::Writer(&d).U16(0);
    uint16_t entries = 0;
    for (const auto& [key, st] : store) {
      if (d.size() + kMinEntryBytes + kCrcBytes > kMaxDatagramBytes) {
        d[count_at] = static_cast<uint8_t>(entries);
        d[count_at + 1] = static_cast<uint8_t>(entries >> 8);
        datagrams.push_back(std::move(d));
        d = SummaryStart(now);
        count_at = d.size();
        wire::Writer(&d).U16(0);
        entries = 0;
      }
      WriteHoldings(key, st, kMaxDatagramBytes - kCrcBytes, &d);
      ++entries;
    }
    d[count_at] = static_cast<uint8_t>(entries);
    d[count_at + 1] = static_cast<uint8_t>(entries >> 8);
    datagrams.push_back(std::move(d));
    for (std::vector<uint8_t>& datagram : datagrams) {
      SealDatagram(&datagram);
      if (!Spend(datagram.size())) return;  // the rest next time
      Emit(kAllRobots, datagram);
      ++stats->summaries_sent;
    }
    last_summary = now;
  }

  std::vector<uint8_t> FragmentDatagram(const Key& key, uint64_t seq, const Message& m,
                                        uint16_t index) const {
    std::vector<uint8_t> d;
    d.reserve(kMaxDatagramBytes);
    wire::Writer w(&d);
    WriteHeader(&w, kFragmentKind, endpoint->self());
    w.U32(key.origin);
    w.U8(key.stream);
    w.U64(seq);
    w.U32(static_cast<uint32_t>(m.bytes->size()));
    w.U32(m.crc);
    w.U16(index);
    w.U16(m.fragments);
    const std::size_t offset = std::size_t{index} * kFragmentPayloadBytes;
    const std::size_t n = std::min(kFragmentPayloadBytes, m.bytes->size() - offset);
    w.Bytes(std::span<const uint8_t>(*m.bytes).subspan(offset, n));
    SealDatagram(&d);
    return d;
  }

  // Sends `peer` the fragments of message `seq` it lacks; false once the
  // budget is spent.
  bool SendMissing(RobotId id, Peer* peer, const Key& key, uint64_t seq, const Message& m,
                   Time now) {
    const auto h = peer->holdings.find(key);
    if (h != peer->holdings.end() && h->second.Holds(seq)) return true;
    std::vector<Time>& sent = peer->sent[key][seq];
    if (sent.size() != m.fragments) sent.assign(m.fragments, Time::FromNanoseconds(INT64_MIN));
    const Duration resend_after = ResendAfter(*peer);
    for (uint16_t index = 0; index < m.fragments; ++index) {
      if (h != peer->holdings.end() && h->second.HoldsFragment(seq, index)) continue;
      const bool resend = sent[index] != Time::FromNanoseconds(INT64_MIN);
      if (resend && now - sent[index] < resend_after) continue;
      const std::vector<uint8_t> d = FragmentDatagram(key, seq, m, index);
      const int copies = Copies(key.stream);
      if (!Spend(d.size() * static_cast<std::size_t>(copies))) return false;
      for (int k = 0; k < copies; ++k) Emit(id, d);
      sent[index] = now;
      ++stats->fragments_sent;
      stats->fragments_resent += resend ? 1 : 0;
    }
    return true;
  }

  int Copies(uint8_t stream) const {
    return stream < options.copies_by_stream.size() ? options.copies_by_stream[stream] : 1;
  }

  // Streams by number; within one, this rover's own messages first.
  std::vector<Key> SendingOrder() const {
    std::vector<Key> keys;
    for (const auto& [key, st] : store) keys.push_back(key);
    const RobotId self = endpoint->self();
    std::stable_sort(keys.begin(), keys.end(), [self](const Key& a, const Key& b) {
      if (a.stream != b.stream) return a.stream < b.stream;
      return (a.origin == self) > (b.origin == self);
    });
    return keys;
  }

  void SendData(Time now) {
    std::vector<std::pair<RobotId, Peer*>> targets;
    for (auto& [id, p] : peers) {
      if (p.heard && now - p.last_heard < options.peer_silence) targets.emplace_back(id, &p);
    }
    if (targets.empty()) return;
    for (const Key& key : SendingOrder()) {
      const Stream& st = store.at(key);
      uint64_t from = UINT64_MAX;
      for (const auto& [id, p] : targets) {
        if (id == key.origin) continue;  // a rover publishes its own messages again itself
        const auto h = p->holdings.find(key);
        from = std::min(from, h == p->holdings.end() ? 0 : h->second.contiguous);
      }
      if (from == UINT64_MAX) continue;
      for (auto it = st.complete.upper_bound(from); it != st.complete.end(); ++it) {
        for (const auto& [id, p] : targets) {
          if (id == key.origin) continue;
          if (!SendMissing(id, p, key, it->first, it->second, now)) return;
        }
      }
    }
  }
};

TeamSync::TeamSync(LinkEndpoint* endpoint, const TeamSyncOptions& options) {
  if (endpoint == nullptr) throw std::invalid_argument("TeamSync: no link endpoint");
  options.Validate();
  impl_ = std::make_unique<Impl>(endpoint, options, &stats_);
}

TeamSync::~TeamSync() = default;

RobotId TeamSync::self() const { return impl_->endpoint->self(); }

uint64_t TeamSync::Publish(uint8_t stream, std::vector<uint8_t> bytes) {
  if (stream >= kMaxStreams) {
    throw std::invalid_argument("TeamSync::Publish: stream " + std::to_string(stream) +
                                ", expected 0.." + std::to_string(kMaxStreams - 1));
  }
  if (bytes.size() > impl_->options.max_message_bytes) {
    throw std::invalid_argument("TeamSync::Publish: " + std::to_string(bytes.size()) +
                                " bytes, more than max_message_bytes (" +
                                std::to_string(impl_->options.max_message_bytes) + ")");
  }
  Stream& st = impl_->store[{self(), stream}];
  const uint64_t seq = st.contiguous + 1;
  Impl::Complete(&st, seq, MakeMessage(std::move(bytes)));
  ++stats_.published;
  return seq;
}

void TeamSync::Restore(RobotId origin, uint8_t stream, uint64_t seq, std::vector<uint8_t> bytes) {
  if (origin == self()) {
    throw std::invalid_argument(
        "TeamSync::Restore: a message of this rover's own; publish it again with Publish");
  }
  if (stream >= kMaxStreams || seq == 0) {
    throw std::invalid_argument("TeamSync::Restore: stream " + std::to_string(stream) +
                                " message " + std::to_string(seq) + " out of range");
  }
  Stream& st = impl_->store[{origin, stream}];
  if (st.complete.count(seq) != 0) return;
  st.partial.erase(seq);
  Impl::Complete(&st, seq, MakeMessage(std::move(bytes)));
}

void TeamSync::SetHeartbeat(std::vector<uint8_t> bytes) {
  if (bytes.size() > kMaxHeartbeatBytes) {
    throw std::invalid_argument("TeamSync::SetHeartbeat: " + std::to_string(bytes.size()) +
                                " bytes, at most " + std::to_string(kMaxHeartbeatBytes));
  }
  impl_->heartbeat = std::move(bytes);
}

void TeamSync::Tick() {
  const Time now = impl_->endpoint->Now();
  while (std::optional<Datagram> d = impl_->endpoint->Receive()) impl_->Handle(*d, now);
  impl_->Refill(now);
  if (!impl_->last_summary || now - *impl_->last_summary >= impl_->options.summary_interval) {
    impl_->SendSummaries(now);
  }
  impl_->SendData(now);
}

std::vector<TeamMessage> TeamSync::TakeDelivered() {
  std::vector<TeamMessage> out(std::make_move_iterator(impl_->delivered.begin()),
                               std::make_move_iterator(impl_->delivered.end()));
  impl_->delivered.clear();
  return out;
}

bool TeamSync::Has(RobotId origin, uint8_t stream, uint64_t seq) const {
  const auto it = impl_->store.find({origin, stream});
  return it != impl_->store.end() && it->second.complete.count(seq) != 0;
}

uint64_t TeamSync::ContiguousCount(RobotId origin, uint8_t stream) const {
  const auto it = impl_->store.find({origin, stream});
  return it == impl_->store.end() ? 0 : it->second.contiguous;
}

std::vector<TeamPeer> TeamSync::peers() const {
  std::vector<TeamPeer> out;
  const Time now = impl_->endpoint->Now();
  for (const auto& [id, p] : impl_->peers) {
    TeamPeer t;
    t.id = id;
    t.last_heard = p.last_heard;
    t.round_trip = p.round_trip;
    t.heartbeat = p.heartbeat;
    t.silent = !p.heard || now - p.last_heard >= impl_->options.peer_silence;
    out.push_back(std::move(t));
  }
  return out;
}

}  // namespace rover::link
