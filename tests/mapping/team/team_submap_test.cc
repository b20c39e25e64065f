#include "mapping/team/team_submap.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "core/log/msgs/message_traits.h"
#include "mapping/submap/submap_messages.h"
#include "mapping/team/team_message.h"
#include "tests/mapping/team/expect_refused.h"

namespace rover::mapping {
namespace {

using testing::ExpectRefused;

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
  // A cloud as mapd builds it: centroids of 5 cm voxels over some ground.
  PointCloud cloud;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> jitter(-0.02f, 0.02f);
  for (int x = -100; x < 100; ++x) {
    for (int y = -60; y < 60; y += 2) {
      CloudPoint p;
      p.p_submap_m = Eigen::Vector3f(0.05f * static_cast<float>(x) + jitter(rng),
                                     0.05f * static_cast<float>(y) + jitter(rng),
                                     -0.35f + 0.1f * std::sin(0.1f * static_cast<float>(x)));
      p.obstacle = (x * y) % 17 == 0;
      cloud.push_back(p);
    }
  }
  s.cloud = ToPointCloud2(cloud, s.info.header);
  return s;
}

TEST(TeamSubmapTest, ASubmapArrivesAsTheSenderLoggedItToTheMillimetreAndSmaller) {
  const TeamSubmap sent = SomeSubmap();
  const std::vector<uint8_t> bytes = EncodeSubmap(sent);
  const std::size_t raw = log::SerializedSize(sent.info) + log::SerializedSize(sent.octomap) +
                          log::SerializedSize(sent.cloud);
  EXPECT_LT(bytes.size(), raw / 3) << "compressed " << bytes.size() << " of " << raw;
  const TeamSubmap got = DecodeSubmap(bytes);
  EXPECT_EQ(got.info, sent.info);
  EXPECT_EQ(got.octomap, sent.octomap);
  EXPECT_EQ(got.cloud.fields, sent.cloud.fields);
  EXPECT_EQ(got.cloud.header, sent.cloud.header);
  const PointCloud a = FromPointCloud2(sent.cloud);
  const PointCloud b = FromPointCloud2(got.cloud);
  ASSERT_EQ(a.size(), b.size());
  float worst = 0.0f;
  for (std::size_t k = 0; k < a.size(); ++k) {
    worst = std::max(worst, (a[k].p_submap_m - b[k].p_submap_m).cwiseAbs().maxCoeff());
    ASSERT_EQ(a[k].obstacle, b[k].obstacle) << k;
  }
  EXPECT_LE(worst, 0.0005f + 1e-6f);
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
