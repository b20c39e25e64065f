#ifndef ROVER_TESTS_HIL_SIM_RENDER_TAG_DETECTION_H_
#define ROVER_TESTS_HIL_SIM_RENDER_TAG_DETECTION_H_

// AprilTag 36h11 detection on rendered images, for the simulator's checks.

#include <Eigen/Core>
#include <array>
#include <opencv2/core.hpp>
#include <vector>

namespace rover::sim {

struct Detection {
  int id = 0;
  std::array<Eigen::Vector2d, 4> corners_px;  // apriltag order, OpenCV convention
};

/// All tag36h11 detections in an 8-bit mono image (full resolution, edges
/// refined), with corners shifted to OpenCV's pixel-centre convention.
std::vector<Detection> DetectTags(const cv::Mat& image);

}  // namespace rover::sim

#endif  // ROVER_TESTS_HIL_SIM_RENDER_TAG_DETECTION_H_
