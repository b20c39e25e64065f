#ifndef ROVER_ESTIMATOR_FEED_KEYFRAME_AT_FILTER_INIT_H_
#define ROVER_ESTIMATOR_FEED_KEYFRAME_AT_FILTER_INIT_H_

// When the VO must drop its keyframe because the filter started after it.
//
// The filter clones poses only from its initialisation on, so a relative
// pose from a keyframe captured before that cannot be used. The VO therefore
// takes a fresh keyframe at the first frame captured at or after the
// initialisation (a clone trigger at the initialising sample's stamp comes
// after that sample in the input order, so its clone exists). One rule for
// roverd's VO thread and `rover-eval vio`, so both feed the filter the same
// relative poses.

#include <cstdint>
#include <optional>

#include "core/time/time.h"

namespace rover::estimator {

class KeyframeAtFilterInit {
 public:
  /// Called once per frame, in capture order, before the VO processes it.
  /// `filter_init` is the stamp of the IMU sample that initialised the
  /// filter, if it has, as of every sample up to `capture` (roverd's
  /// lockstep gate and rover-eval vio both guarantee that). True when the VO
  /// must be asked for a new keyframe at this frame: the first frame at or
  /// after the initialisation, unless it is the VO's first frame anyway.
  bool ShouldRequest(Time capture, std::optional<Time> filter_init) {
    if (decided_) return false;
    if (!filter_init || capture < *filter_init) {
      ++frames_before_;
      return false;
    }
    decided_ = true;
    return frames_before_ > 0;
  }

  /// True once the rule has fired (or found the first frame needs nothing).
  bool decided() const { return decided_; }

 private:
  bool decided_ = false;
  uint64_t frames_before_ = 0;
};

}  // namespace rover::estimator

#endif  // ROVER_ESTIMATOR_FEED_KEYFRAME_AT_FILTER_INIT_H_
