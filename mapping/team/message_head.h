#ifndef ROVER_MAPPING_TEAM_MESSAGE_HEAD_H_
#define ROVER_MAPPING_TEAM_MESSAGE_HEAD_H_

// Internal to mapping/team: the version and kind byte every team encoding
// starts with, and the checks of a decoder's head and end.

#include <cstdint>
#include <string>

#include "core/link/wire.h"
#include "mapping/team/team_message.h"

namespace rover::mapping::team_internal {

enum class Kind : uint8_t { kConstraint = 1, kMatchClaim = 2, kHeartbeat = 3, kSubmap = 4 };

inline const char* Name(Kind kind) {
  switch (kind) {
    case Kind::kConstraint:
      return "team constraint";
    case Kind::kMatchClaim:
      return "team match claim";
    case Kind::kHeartbeat:
      return "team heartbeat";
    case Kind::kSubmap:
      return "team submap";
  }
  return "team message";
}

inline void WriteHead(link::wire::Writer* w, Kind kind) {
  w->U8(kTeamMessageVersion);
  w->U8(static_cast<uint8_t>(kind));
}

// Reads and checks the version and kind; throws naming what was found.
inline void ReadHead(link::wire::Reader* r, Kind kind) {
  const uint8_t version = r->U8();
  const uint8_t found = r->U8();
  if (r->failed()) throw TeamMessageError(std::string(Name(kind)) + ": truncated header");
  if (version != kTeamMessageVersion) {
    throw TeamMessageError(std::string(Name(kind)) + ": version " + std::to_string(version) +
                           ", expected " + std::to_string(kTeamMessageVersion));
  }
  if (found != static_cast<uint8_t>(kind)) {
    throw TeamMessageError(std::string(Name(kind)) + ": kind " + std::to_string(found) +
                           ", expected " + std::to_string(static_cast<int>(kind)));
  }
}

inline void CheckEnd(const link::wire::Reader& r, Kind kind) {
  if (r.failed()) throw TeamMessageError(std::string(Name(kind)) + ": truncated");
  if (r.remaining() != 0) {
    throw TeamMessageError(std::string(Name(kind)) + ": " + std::to_string(r.remaining()) +
                           " bytes after the end");
  }
}

}  // namespace rover::mapping::team_internal

#endif  // ROVER_MAPPING_TEAM_MESSAGE_HEAD_H_
