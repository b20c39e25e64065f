#ifndef ROVER_MAPPING_TAGS_TAG_LOG_H_
#define ROVER_MAPPING_TAGS_TAG_LOG_H_

// Where mapd logs its tag observations, and reading them back: every
// decoded tag (accepted or with its refusal), with the corners, both pose
// solutions and the covariance, so that detections can be replayed and
// scored without the images.

#include <string>
#include <string_view>
#include <vector>

#include "core/log/msgs/rover_msgs.h"

namespace rover::mapping {

/// rover_msgs/TagDetection, one message per decoded tag; header.frame_id
/// names the camera ("cam0": the rectified left camera).
inline constexpr std::string_view kTagDetectionTopic = "/mapd/tags";

struct TagDetectionLog {
  std::vector<log::rover_msgs::TagDetection> detections;  ///< in log order
  std::vector<std::string> problems;                      ///< messages that could not be decoded
};

/// The tag observations in one mapd log. Throws std::runtime_error naming
/// the file if it cannot be read as MCAP; undecodable messages are listed in
/// `problems` and skipped.
TagDetectionLog ReadTagDetections(const std::string& path);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_TAGS_TAG_LOG_H_
