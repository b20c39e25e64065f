#include "firmware/mapd/local_mapper.h"

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

namespace rover::mapd {
namespace {

calib::StereoRectifier MakeRectifier(const calib::CameraModel& cam0,
                                     const calib::CameraModel& cam1) {
  std::optional<calib::StereoRectifier> r = calib::StereoRectifier::Create(cam0, cam1);
  if (!r) {
    throw std::invalid_argument(
        "LocalMapper: the stereo calibration is unusable (sizes differ or are zero, focal "
        "lengths not positive, or cam1 is not to the right of cam0)");
  }
  return *std::move(r);
}

mapping::RectifiedStereo StereoOf(const calib::StereoRectifier& r) {
  mapping::RectifiedStereo s;
  s.width_px = r.image_size().width;
  s.height_px = r.image_size().height;
  s.focal_px = r.intrinsics().fx;
  s.cx_px = r.intrinsics().cx;
  s.cy_px = r.intrinsics().cy;
  s.baseline_m = r.baseline_m();
  s.Validate();
  return s;
}

double MillisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace

void LocalMapperOptions::Validate() const {
  disparity.Validate();
  depth.Validate();
  if (!(pixel_error_px > 0.0)) {
    throw std::invalid_argument("LocalMapperOptions.pixel_error_px: expected > 0, got " +
                                std::to_string(pixel_error_px));
  }
  height_map.Validate();
  steps.Validate();
  negative_edges.Validate();
  obstacle_cells.Validate();
  if (min_obstacle_images < 1 || min_obstacle_images > 255) {
    throw std::invalid_argument("LocalMapperOptions.min_obstacle_images: expected 1..255, got " +
                                std::to_string(min_obstacle_images));
  }
  traversability.Validate();
}

LocalMapper::LocalMapper(const LocalMapperOptions& options, const calib::CameraModel& cam0,
                         const calib::CameraModel& cam1)
    : options_((options.Validate(), options)),
      rectifier_(MakeRectifier(cam0, cam1)),
      stereo_(StereoOf(rectifier_)),
      error_model_(stereo_, options.pixel_error_px),
      // The texture threshold counts sensor noise, which the rectifier's
      // flat field brightens towards the corners.
      disparity_(options.disparity, rectifier_.FlatFieldGain(0)),
      steps_(options.steps, error_model_),
      edges_(options.negative_edges),
      obstacle_marker_(options.obstacle_cells, options.steps),
      grid_(options.traversability),
      T_body_cam_(rectifier_.T_body_cam0rect()) {}

void LocalMapper::ResetTraversability() {
  grid_ = mapping::TraversabilityGrid(options_.traversability);
}

MappedImage LocalMapper::Process(const cv::Mat& raw0, const cv::Mat& raw1,
                                 const Eigen::Isometry3d& T_local_body, mapping::Submap* submap) {
  MappedImage out;
  auto start = std::chrono::steady_clock::now();
  if (!rectifier_.Rectify(raw0, raw1, &rect0_, &rect1_)) {
    throw std::invalid_argument("LocalMapper: expected a mono8 pair of " +
                                std::to_string(stereo_.width_px) + "x" +
                                std::to_string(stereo_.height_px) + " px, got " +
                                std::to_string(raw0.cols) + "x" + std::to_string(raw0.rows));
  }
  disparity_.Compute(rect0_, rect1_, &disparity_q4_);
  depth_ = mapping::DepthImage::FromDisparity(disparity_q4_, error_model_, options_.depth);
  has_depth_ = true;
  out.depth = depth_.counts();
  out.disparity_ms = MillisecondsSince(start);

  // The local frame is gravity-aligned (z up), so it is the frame the
  // slopes and heights are judged in.
  start = std::chrono::steady_clock::now();
  const Eigen::Isometry3d T_local_cam = T_local_body * T_body_cam_;
  const mapping::HeightMap heights =
      mapping::HeightMap::Build(depth_, T_local_cam, options_.height_map);
  const mapping::StepGrid steps = steps_.Classify(heights, T_local_cam);
  const std::vector<mapping::NegativeEdge> edges = edges_.Detect(depth_, T_local_cam);
  grid_.Recentre(T_local_body.translation().head<2>());
  grid_.Add(steps, edges);
  out.negative_edges = static_cast<int>(edges.size());
  obstacle_marker_.Mark(steps, heights, &obstacle_cells_);
  grid_.CountObstacles(obstacle_cells_);
  grid_.KeepConfirmed(options_.min_obstacle_images, &obstacle_cells_);
  out.obstacle_points = MarkObstacles(edges, T_local_cam);
  out.classification_ms = MillisecondsSince(start);

  start = std::chrono::steady_clock::now();
  submap->Integrate(depth_, obstacle_mask_, T_local_cam);
  out.insertion_ms = MillisecondsSince(start);
  return out;
}

int LocalMapper::MarkObstacles(const std::vector<mapping::NegativeEdge>& edges,
                               const Eigen::Isometry3d& T_local_cam) {
  const int w = depth_.width();
  const int h = depth_.height();
  obstacle_mask_.assign(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), 0);
  int flagged = 0;
  const Eigen::Isometry3f T = T_local_cam.cast<float>();
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      if (depth_.state(u, v) != mapping::DepthState::kValid) continue;
      const Eigen::Vector3f p = T * depth_.point(u, v);
      int ix = 0, iy = 0;
      if (!obstacle_cells_.CellOf(p, &ix, &iy) || !obstacle_cells_.Obstacle(ix, iy)) continue;
      obstacle_mask_[static_cast<std::size_t>(v) * static_cast<std::size_t>(w) +
                     static_cast<std::size_t>(u)] = 1;
      ++flagged;
    }
  }
  // A negative edge is the near side of a drop: the point at its pixel.
  for (const mapping::NegativeEdge& e : edges) {
    if (e.u < 0 || e.v < 0 || e.u >= w || e.v >= h) continue;
    uint8_t& m = obstacle_mask_[static_cast<std::size_t>(e.v) * static_cast<std::size_t>(w) +
                                static_cast<std::size_t>(e.u)];
    if (m == 0 && depth_.state(e.u, e.v) == mapping::DepthState::kValid) ++flagged;
    m = 1;
  }
  return flagged;
}

}  // namespace rover::mapd
