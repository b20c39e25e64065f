#include "mapping/team/team_message.h"
#include "tests/mapping/team/expect_refused.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace rover::mapping {
namespace {

using testing::ExpectRefused;

Eigen::Isometry3d Pose(double x, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, -2.0, 0.3);
  return T;
}

TEST(TeamMessageTest, AConstraintArrivesAsTheSenderLoggedIt) {
  Matrix6d covariance = Matrix6d::Identity() * 0.01;
  covariance(0, 1) = covariance(1, 0) = 0.002;
  GraphFactorRecord sent =
      SubmapMatchFactor(GraphKey::Origin(1, 4), GraphKey::Origin(2, 9), Pose(3.5, 0.4), covariance);
  sent.id = 77;
  sent.stamp_ns = 123456789;
  const GraphFactorRecord got = DecodeConstraint(EncodeConstraint(sent));
  // What mapd logs: FromMsg(ToMsg(r)) (the rotation travels as a quaternion).
  const GraphFactorRecord logged = FromMsg(ToMsg(sent, "robot1"));
  EXPECT_EQ(got.id, 77u);
  EXPECT_EQ(got.stamp_ns, sent.stamp_ns);
  EXPECT_EQ(got.kind, FactorKind::kSubmapMatch);
  EXPECT_EQ(got.a, sent.a);
  EXPECT_EQ(got.b, sent.b);
  EXPECT_TRUE(got.robust);
  EXPECT_EQ(got.T_a_b.matrix(), logged.T_a_b.matrix());
  EXPECT_EQ(got.covariance, logged.covariance);
}

TEST(TeamMessageTest, ClaimsAndHeartbeatsRoundTrip) {
  const MatchClaim claim{GraphKey::Origin(1, 3), GraphKey::Origin(2, 17), 2};
  EXPECT_EQ(DecodeMatchClaim(EncodeMatchClaim(claim)), claim);
  TeamHeartbeat h;
  h.stamp_ns = 42;
  h.submap = 12;
  h.T_world_body = Pose(-7.25, 2.0);
  const std::vector<uint8_t> bytes = EncodeHeartbeat(h);
  EXPECT_EQ(bytes.size(), 74u);
  const TeamHeartbeat got = DecodeHeartbeat(bytes);
  EXPECT_EQ(got.stamp_ns, 42);
  EXPECT_EQ(got.submap, 12);
  EXPECT_TRUE(got.T_world_body.isApprox(h.T_world_body, 1e-12));
}

TEST(TeamMessageTest, MalformedMessagesAreRefusedNamingWhatIsWrong) {
  const MatchClaim claim{GraphKey::Origin(1, 3), GraphKey::Origin(2, 17), 2};
  std::vector<uint8_t> bytes = EncodeMatchClaim(claim);
  std::vector<uint8_t> v2 = bytes;
  v2[0] = 2;
  ExpectRefused([&] { DecodeMatchClaim(v2); }, "version 2, expected 1");
  ExpectRefused([&] { DecodeHeartbeat(bytes); }, "kind 2, expected 3");
  std::vector<uint8_t> shorter(bytes.begin(), bytes.end() - 1);
  ExpectRefused([&] { DecodeMatchClaim(shorter); }, "truncated");
  std::vector<uint8_t> longer = bytes;
  longer.push_back(0);
  ExpectRefused([&] { DecodeMatchClaim(longer); }, "1 bytes after the end");
  ExpectRefused([&] { DecodeMatchClaim(EncodeMatchClaim({claim.a, claim.a, 1})); }, "with itself");
  ExpectRefused(
      [&] {
        DecodeMatchClaim(EncodeMatchClaim({claim.a, GraphKey::Landmark(4), 1}));
      },
      "expected two submap origins, found l4");
  TeamHeartbeat h;
  h.T_world_body.translation().x() = std::nan("");
  ExpectRefused([&] { DecodeHeartbeat(EncodeHeartbeat(h)); }, "not finite");
  GraphFactorRecord f = SubmapMatchFactor(GraphKey::Origin(1, 4), GraphKey::Origin(2, 9),
                                          Pose(1.0, 0.0), Matrix6d::Identity());
  std::vector<uint8_t> cdr = EncodeConstraint(f);
  cdr.resize(cdr.size() / 2);
  ExpectRefused([&] { DecodeConstraint(cdr); }, "team constraint");
  f.covariance(2, 2) = std::nan("");
  ExpectRefused([&] { DecodeConstraint(EncodeConstraint(f)); }, "team constraint");
}

}  // namespace
}  // namespace rover::mapping
