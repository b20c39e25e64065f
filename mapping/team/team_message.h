#ifndef ROVER_MAPPING_TEAM_TEAM_MESSAGE_H_
#define ROVER_MAPPING_TEAM_TEAM_MESSAGE_H_

// What rovers of a team tell each other over the team link (core/link's
// TeamSync carries the bytes): the constraints of each rover's graph, claims
// on submap pairs so that no two rovers match the same pair, and a heartbeat
// with each rover's latest global pose.
//
// Every encoding starts with a version and a kind byte; a decoder refuses
// another version or kind, truncated or trailing bytes, and values the graph
// cannot take, with a TeamMessageError naming the message and the field.

#include <Eigen/Geometry>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <vector>

#include "mapping/graph/graph_key.h"
#include "mapping/slam/graph_factor_record.h"

namespace rover::mapping {

/// The team link's streams (TeamSync stream numbers: a lower one goes first
/// when the link's budget is short).
enum class TeamStream : uint8_t { kConstraints = 0, kMatchClaims = 1, kSubmaps = 2 };

/// Version of the encodings below.
inline constexpr uint8_t kTeamMessageVersion = 1;

class TeamMessageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A constraint: one factor of the sender's graph, as mapd logs it (ROS 2
/// CDR of rover_msgs/GraphFactor), so the receiver's log holds it in the same
/// form as its own.
std::vector<uint8_t> EncodeConstraint(const GraphFactorRecord& record);
/// The same for a factor as it was logged: the receiver gets these bits, so
/// every rover's graph holds the same numbers.
std::vector<uint8_t> EncodeConstraint(const log::rover_msgs::GraphFactor& msg);
/// Throws TeamMessageError for another version or kind, bad CDR, or a
/// factor FromMsg refuses (naming its id and field).
GraphFactorRecord DecodeConstraint(std::span<const uint8_t> bytes);
/// The constraint's message as the sender logged it, checked as above.
log::rover_msgs::GraphFactor DecodeConstraintMessage(std::span<const uint8_t> bytes);

/// Robot `claimant` matches origins `a` and `b`; no other rover computes or
/// counts that pair (the thesis's announced match attempts).
struct MatchClaim {
  GraphKey a;
  GraphKey b;
  uint32_t claimant = 0;
  friend bool operator==(const MatchClaim&, const MatchClaim&) = default;
};
std::vector<uint8_t> EncodeMatchClaim(const MatchClaim& claim);
/// Throws TeamMessageError unless both keys are submap origins of different
/// submaps.
MatchClaim DecodeMatchClaim(std::span<const uint8_t> bytes);

/// A rover's latest global pose s_j (+) v_t and the submap it is mapping.
struct TeamHeartbeat {
  int64_t stamp_ns = 0;
  int64_t submap = 0;
  Eigen::Isometry3d T_world_body = Eigen::Isometry3d::Identity();
};
/// 74 bytes (TeamSync carries up to 256 in every summary).
std::vector<uint8_t> EncodeHeartbeat(const TeamHeartbeat& heartbeat);
/// Throws TeamMessageError for a non-finite pose or a rotation that is not
/// one.
TeamHeartbeat DecodeHeartbeat(std::span<const uint8_t> bytes);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_TEAM_TEAM_MESSAGE_H_
