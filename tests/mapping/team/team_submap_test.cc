#include "mapping/team/team_submap.h"

#include <gtest/gtest.h>

#include <string>

#include "mapping/team/team_message.h"

namespace rover::mapping {
namespace {

TeamSubmap SomeSubmap() {
  TeamSubmap s;
  s.info.header.frame_id = log::FrameId::Truncated("local/rover_b/4");
  s.info.index = 3;
  s.info.frame_id = 4;
  s.info.has_origin = true;
  s.info.p_previous_origin_m = {6.5, 0.25, 0.0};
  s.info.distance_m = 6.7;
  s.octomap.header = s.info.header;
  s.octomap.id = "OcTree";
  s.octomap.resolution = 0.1;
  s.octomap.binary = true;
  // Octree bytes repeat (free space, many identical nodes): they compress.
  s.octomap.data.resize(60000);
  for (std::size_t k = 0; k < s.octomap.data.size(); ++k) {
    s.octomap.data[k] = static_cast<int8_t>((k % 7 == 0) ? 0x55 : 0);
  }
  s.cloud.header = s.info.header;
  s.cloud.height = 1;
  s.cloud.width = 100;
  s.cloud.point_step = 12;
  s.cloud.row_step = 1200;
  s.cloud.data.resize(1200);
  for (std::size_t k = 0; k < s.cloud.data.size(); ++k) {
    s.cloud.data[k] = static_cast<uint8_t>(k * 37);
  }
  return s;
}

template <typename F>
void ExpectRefused(F f, const std::string& needle) {
  try {
    f();
    ADD_FAILURE() << "accepted; expected a refusal mentioning '" << needle << "'";
  } catch (const TeamMessageError& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(TeamSubmapTest, ASubmapArrivesAsTheSenderLoggedItAndSmaller) {
  const TeamSubmap sent = SomeSubmap();
  const std::vector<uint8_t> bytes = EncodeSubmap(sent);
  EXPECT_LT(bytes.size(), 61200u / 4) << "compressed";
  const TeamSubmap got = DecodeSubmap(bytes);
  EXPECT_EQ(got.info, sent.info);
  EXPECT_EQ(got.octomap, sent.octomap);
  EXPECT_EQ(got.cloud, sent.cloud);
}

TEST(TeamSubmapTest, DamageTruncationAndHostileSizesAreRefusedByName) {
  const std::vector<uint8_t> good = EncodeSubmap(SomeSubmap());
  ExpectRefused([&] { DecodeSubmap(std::span(good).first(5)); }, "truncated");
  std::vector<uint8_t> flipped = good;
  flipped[flipped.size() / 2] ^= 0xFF;
  ExpectRefused([&] { DecodeSubmap(flipped); }, "team submap");
  std::vector<uint8_t> huge = good;
  huge[2 + 7] = 0x7F;  // the stated size's top byte
  ExpectRefused([&] { DecodeSubmap(huge); }, "accepted");
  std::vector<uint8_t> version = good;
  version[0] = 99;
  ExpectRefused([&] { DecodeSubmap(version); }, "version 99");
  ExpectRefused([&] { DecodeSubmap(EncodeHeartbeat({})); }, "kind 3");
}

}  // namespace
}  // namespace rover::mapping
