#include "firmware/mapd/team_config.h"

#include <set>

#include "core/link/dds/dds_link.h"

namespace rover::mapd {

const TeamMember& TeamConfig::Self() const {
  for (const TeamMember& m : robots) {
    if (m.id == self) return m;
  }
  throw std::logic_error("TeamConfig: robot " + std::to_string(self) + " is not in the team");
}

std::vector<std::string> TeamConfig::PeerAddresses() const {
  std::vector<std::string> out;
  for (const TeamMember& m : robots) {
    if (m.id != self) out.push_back(m.address);
  }
  return out;
}

std::string TeamConfig::DdsConfigXml() const {
  return link::MakeUnicastConfig(Self().interface_name, PeerAddresses());
}

TeamConfig TeamConfig::Load(const ConfigNode& root, int self_id) {
  TeamConfig c;
  c.domain_id = root.GetInRange<uint32_t>("domain_id", 0, 230, 0);
  std::set<int> ids;
  std::set<std::string> names;
  for (const ConfigNode& node : root.ChildList("robots")) {
    TeamMember m;
    m.id = node.GetInRange<int>("id", 0, 65535);
    m.name = node.Get<std::string>("name");
    m.address = node.Get<std::string>("address");
    m.interface_name = node.Get<std::string>("interface");
    if (!ids.insert(m.id).second) {
      node.Fail("id", "robot id " + std::to_string(m.id) + " is used twice in the team");
    }
    if (!names.insert(m.name).second) {
      node.Fail("name", "robot name " + m.name + " is used twice in the team");
    }
    c.worker.sync.team.push_back(static_cast<link::RobotId>(m.id));
    c.robots.push_back(std::move(m));
  }
  if (ids.count(self_id) == 0) {
    std::string known;
    for (const int id : ids) known += (known.empty() ? "" : ", ") + std::to_string(id);
    root.Fail("robots", "has no robot with id " + std::to_string(self_id) + " (this rover's; " +
                            "the team has " + known + ")");
  }
  c.self = self_id;
  if (root.Has("link")) {
    const ConfigNode link = root.Child("link");
    link::TeamSyncOptions& s = c.worker.sync;
    s.budget_bytes_per_s =
        link.GetInRange<double>("budget_bytes_per_s", 100.0, 1e9, s.budget_bytes_per_s);
    s.burst_bytes = link.GetInRange<double>("burst_bytes", 1500.0, 1e9, s.burst_bytes);
    const auto seconds = [&link](const char* key, double lo, double hi, Duration fallback) {
      return Duration::FromSeconds(link.GetInRange<double>(key, lo, hi, fallback.ToSeconds()));
    };
    s.summary_interval = seconds("summary_interval_s", 0.01, 60.0, s.summary_interval);
    s.min_resend = seconds("min_resend_s", 0.01, 600.0, s.min_resend);
    s.initial_round_trip = seconds("initial_round_trip_s", 0.001, 600.0, s.initial_round_trip);
    s.peer_silence = seconds("peer_silence_s", 0.1, 86400.0, s.peer_silence);
  }
  c.worker.Validate();
  return c;
}

}  // namespace rover::mapd
