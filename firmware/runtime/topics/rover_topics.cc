#include "firmware/runtime/topics/rover_topics.h"

namespace rover::runtime::topics {

std::string_view ToString(SwitchReason reason) {
  switch (reason) {
    case SwitchReason::kDistance:
      return "distance";
    case SwitchReason::kPositionSigma:
      return "position_sigma";
    case SwitchReason::kRestart:
      return "restart";
  }
  return "unknown";
}

}  // namespace rover::runtime::topics
