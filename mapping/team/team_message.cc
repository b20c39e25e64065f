#include "mapping/team/team_message.h"

#include <cmath>
#include <string>

#include "core/link/wire.h"
#include "core/log/msgs/message_traits.h"
#include "core/log/msgs/rover_msgs.h"
#include "mapping/team/message_head.h"

namespace rover::mapping {
namespace {

using team_internal::CheckEnd;
using team_internal::Kind;
using team_internal::Name;
using team_internal::ReadHead;
using team_internal::WriteHead;

void WriteKey(link::wire::Writer* w, const GraphKey& key) {
  w->U8(static_cast<uint8_t>(key.type));
  w->U32(static_cast<uint32_t>(key.robot));
  w->I64(key.index);
}

GraphKey ReadKey(link::wire::Reader* r) {
  GraphKey key;
  key.type = static_cast<GraphKey::Type>(r->U8());
  key.robot = static_cast<int>(r->U32());
  key.index = r->I64();
  return key;
}

}  // namespace

std::vector<uint8_t> EncodeConstraint(const GraphFactorRecord& record) {
  return EncodeConstraint(ToMsg(record, "robot" + std::to_string(record.a.robot)));
}

std::vector<uint8_t> EncodeConstraint(const log::rover_msgs::GraphFactor& msg) {
  std::vector<uint8_t> out;
  link::wire::Writer w(&out);
  WriteHead(&w, Kind::kConstraint);
  const std::vector<std::byte> cdr = log::SerializeMessage(msg);
  w.Bytes(std::span(reinterpret_cast<const uint8_t*>(cdr.data()), cdr.size()));
  return out;
}

log::rover_msgs::GraphFactor DecodeConstraintMessage(std::span<const uint8_t> bytes) {
  link::wire::Reader r(bytes);
  ReadHead(&r, Kind::kConstraint);
  const std::span<const uint8_t> cdr = r.Bytes(r.remaining());
  log::rover_msgs::GraphFactor msg;
  std::string error;
  if (!log::DeserializeMessage(std::as_bytes(cdr), &msg, &error)) {
    throw TeamMessageError(std::string(Name(Kind::kConstraint)) + ": " + error);
  }
  try {
    FromMsg(msg);  // refuses what the graph cannot take
  } catch (const GraphError& e) {
    throw TeamMessageError(std::string(Name(Kind::kConstraint)) + ": " + e.what());
  }
  return msg;
}

GraphFactorRecord DecodeConstraint(std::span<const uint8_t> bytes) {
  return FromMsg(DecodeConstraintMessage(bytes));
}

std::vector<uint8_t> EncodeMatchClaim(const MatchClaim& claim) {
  std::vector<uint8_t> out;
  link::wire::Writer w(&out);
  WriteHead(&w, Kind::kMatchClaim);
  WriteKey(&w, claim.a);
  WriteKey(&w, claim.b);
  w.U32(claim.claimant);
  return out;
}

MatchClaim DecodeMatchClaim(std::span<const uint8_t> bytes) {
  link::wire::Reader r(bytes);
  ReadHead(&r, Kind::kMatchClaim);
  MatchClaim claim;
  claim.a = ReadKey(&r);
  claim.b = ReadKey(&r);
  claim.claimant = r.U32();
  CheckEnd(r, Kind::kMatchClaim);
  for (const GraphKey* key : {&claim.a, &claim.b}) {
    if (key->type != GraphKey::Type::kOrigin || key->robot < 0 || key->index < 0) {
      throw TeamMessageError(std::string(Name(Kind::kMatchClaim)) +
                             ": expected two submap origins, found " + key->ToString());
    }
  }
  if (claim.a == claim.b) {
    throw TeamMessageError(std::string(Name(Kind::kMatchClaim)) + ": " + claim.a.ToString() +
                           " with itself");
  }
  return claim;
}

std::vector<uint8_t> EncodeHeartbeat(const TeamHeartbeat& heartbeat) {
  std::vector<uint8_t> out;
  link::wire::Writer w(&out);
  WriteHead(&w, Kind::kHeartbeat);
  w.I64(heartbeat.stamp_ns);
  w.I64(heartbeat.submap);
  const Eigen::Vector3d p = heartbeat.T_world_body.translation();
  const Eigen::Quaterniond q(heartbeat.T_world_body.rotation());
  for (const double v : {p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z()}) w.F64(v);
  return out;
}

TeamHeartbeat DecodeHeartbeat(std::span<const uint8_t> bytes) {
  link::wire::Reader r(bytes);
  ReadHead(&r, Kind::kHeartbeat);
  TeamHeartbeat h;
  h.stamp_ns = r.I64();
  h.submap = r.I64();
  double v[7];
  for (double& x : v) x = r.F64();
  CheckEnd(r, Kind::kHeartbeat);
  const Eigen::Quaterniond q(v[3], v[4], v[5], v[6]);
  bool finite = true;
  for (const double x : v) finite = finite && std::isfinite(x);
  if (!finite || std::abs(q.norm() - 1.0) > 1e-6) {
    throw TeamMessageError(std::string(Name(Kind::kHeartbeat)) +
                           ": the pose is not finite or its quaternion not of unit norm");
  }
  h.T_world_body = Eigen::Isometry3d::Identity();
  h.T_world_body.linear() = q.normalized().toRotationMatrix();
  h.T_world_body.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
  return h;
}

}  // namespace rover::mapping
