#include "tests/hil/sim/render/tag_detection.h"

#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>

namespace rover::sim {
namespace {
// apriltag reports corners with pixel centres at +0.5; OpenCV at 0.
constexpr double kApriltagCentreOffsetPx = 0.5;
}  // namespace

std::vector<Detection> DetectTags(const cv::Mat& image) {
  apriltag_family_t* family = tag36h11_create();
  apriltag_detector_t* detector = apriltag_detector_create();
  apriltag_detector_add_family(detector, family);
  detector->quad_decimate = 1.0f;
  detector->quad_sigma = 0.0f;
  detector->refine_edges = true;
  detector->nthreads = 1;
  // Debian's libapriltag does not export image_u8_create; the detector only
  // reads the struct, so it can wrap the Mat's rows directly.
  CV_Assert(image.type() == CV_8UC1);
  image_u8_t im = {image.cols, image.rows, static_cast<int32_t>(image.step[0]),
                   const_cast<uint8_t*>(image.ptr<uint8_t>(0))};
  zarray_t* detections = apriltag_detector_detect(detector, &im);
  std::vector<Detection> out;
  for (int i = 0; i < zarray_size(detections); ++i) {
    apriltag_detection_t* det = nullptr;
    zarray_get(detections, i, &det);
    Detection d;
    d.id = det->id;
    for (std::size_t c = 0; c < 4; ++c) {
      d.corners_px[c] = Eigen::Vector2d(det->p[c][0] - kApriltagCentreOffsetPx,
                                        det->p[c][1] - kApriltagCentreOffsetPx);
    }
    out.push_back(d);
  }
  apriltag_detections_destroy(detections);
  apriltag_detector_destroy(detector);
  tag36h11_destroy(family);
  return out;
}

}  // namespace rover::sim
