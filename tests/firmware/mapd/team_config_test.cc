#include "firmware/mapd/team_config.h"

#include <gtest/gtest.h>

#include <functional>
#include <string>

namespace rover::mapd {
namespace {

constexpr const char* kTeam = R"(
domain_id: 7
robots:
  - {id: 0, name: rover_a, address: 10.77.0.1, interface: r1}
  - {id: 1, name: rover_b, address: 10.77.0.2, interface: r2}
  - {id: 2, name: rover_c, address: 10.77.0.3, interface: r3}
link:
  budget_bytes_per_s: 20000
  summary_interval_s: 0.25
)";

TeamConfig Load(const std::string& yaml, int self) {
  const ConfigNode root = ConfigNode::LoadString(yaml, "team.yaml");
  TeamConfig c = TeamConfig::Load(root, self);
  root.CheckNoUnknownKeysRecursive();
  return c;
}

void ExpectRefused(const std::function<void()>& f, const std::string& part) {
  try {
    f();
    ADD_FAILURE() << "accepted; expected an error containing: " << part;
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

TEST(TeamConfigTest, ARoverFindsItselfItsPeersAndTheLinkOptions) {
  const TeamConfig c = Load(kTeam, 1);
  EXPECT_EQ(c.domain_id, 7u);
  EXPECT_EQ(c.Self().name, "rover_b");
  EXPECT_EQ(c.Self().interface_name, "r2");
  EXPECT_EQ(c.PeerAddresses(), (std::vector<std::string>{"10.77.0.1", "10.77.0.3"}));
  EXPECT_EQ(c.worker.sync.team, (std::vector<link::RobotId>{0, 1, 2}));
  EXPECT_DOUBLE_EQ(c.worker.sync.budget_bytes_per_s, 20000.0);
  EXPECT_EQ(c.worker.sync.summary_interval, Duration::Milliseconds(250));
  const std::string xml = c.DdsConfigXml();
  EXPECT_NE(xml.find("r2"), std::string::npos) << xml;
  EXPECT_NE(xml.find("10.77.0.3"), std::string::npos) << xml;
  EXPECT_EQ(xml.find("10.77.0.2"), std::string::npos) << "not its own address: " << xml;
}

TEST(TeamConfigTest, ARobotIdUsedTwiceAnUnknownSelfAndTyposAreRefused) {
  ExpectRefused([] { Load(kTeam, 5); },
                "has no robot with id 5 (this rover's; the team has 0, 1, 2)");
  ExpectRefused(
      [] {
        Load(
            "robots:\n  - {id: 0, name: a, address: x, interface: r1}\n"
            "  - {id: 0, name: b, address: y, interface: r2}\n",
            0);
      },
      "robot id 0 is used twice");
  ExpectRefused(
      [] {
        Load(
            "robots:\n  - {id: 0, name: a, address: x, interface: r1}\n"
            "link: {budget_bytes_per_second: 100}\n",
            0);
      },
      "budget_bytes_per_second");
  ExpectRefused([] { Load("robots:\n  - {id: 0, name: a, interface: r1}\n", 0); }, "address");
}

}  // namespace
}  // namespace rover::mapd
