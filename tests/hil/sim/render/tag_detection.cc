#include "tests/hil/sim/render/tag_detection.h"

#include "mapping/tags/tag_detector.h"

namespace rover::sim {

std::vector<Detection> DetectTags(const cv::Mat& image) {
  // Everything the library decodes: the renderer's checks judge the corners
  // themselves, not whether a graph would take them.
  mapping::TagDetectorOptions options;
  options.max_hamming = options.max_bits_corrected;
  options.min_decision_margin = 0.0;
  options.border_margin_px = 0.0;
  options.min_area_px2 = 1e-6;
  options.quad_decimate = 1.0;  // full resolution: the farthest tags too
  mapping::TagDetector detector(options);
  std::vector<Detection> out;
  for (const mapping::TagDetection& d : detector.Detect(image)) {
    out.push_back(Detection{d.id, d.corners_px});
  }
  return out;
}

}  // namespace rover::sim
