#include "mapping/tags/tag_observer.h"

#include <apriltag/apriltag.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>
#include <stdexcept>

#include "core/log/msgs/builtin_interfaces.h"
#include "mapping/slam/graph_log.h"
#include "mapping/tags/tag_family.h"

namespace rover::mapping {
namespace {

int64_t SizeKey(double size_m) { return std::llround(size_m * 1e4); }

std::string SizeText(double size_m) {
  std::ostringstream s;
  s << size_m * 1000.0 << " mm";
  return s.str();
}

}  // namespace

void TagObserverOptions::Validate() const {
  detector.Validate();
  model.Validate();
  if (detector.families.size() != 1) {
    throw std::invalid_argument(
        "TagObserverOptions.families: expected one family (the markers' ids are of one), found " +
        std::to_string(detector.families.size()));
  }
  const TagFamilyPtr family = CreateTagFamily(detector.families[0]);
  std::set<int> ids;
  for (const TagMarker& m : markers) {
    const std::string where = "TagObserverOptions.markers[id " + std::to_string(m.id) + "]";
    if (m.id < 0 || m.id >= static_cast<int>(family->ncodes)) {
      throw std::invalid_argument(where + ".id: expected 0.." + std::to_string(family->ncodes - 1) +
                                  " for " + detector.families[0]);
    }
    if (!ids.insert(m.id).second) throw std::invalid_argument(where + ": configured twice");
    if (!(std::isfinite(m.size_m) && m.size_m > 0.0)) {
      throw std::invalid_argument(where + ".size_m: expected > 0, found " +
                                  std::to_string(m.size_m));
    }
  }
}

TagObserverOptions TagObserverOptions::Load(const ConfigNode& node) {
  TagObserverOptions o;
  o.detector.families = node.Get<std::vector<std::string>>("families", o.detector.families);
  o.detector.max_hamming = node.Get<int>("max_hamming", o.detector.max_hamming);
  o.detector.min_decision_margin =
      node.Get<double>("min_decision_margin", o.detector.min_decision_margin);
  o.detector.quad_decimate = node.Get<double>("quad_decimate", o.detector.quad_decimate);
  o.detector.max_border_offset_px =
      node.Get<double>("max_border_offset_px", o.detector.max_border_offset_px);
  o.model.kind = node.GetEnum<TagErrorModelKind>(
      "model", {{"table", TagErrorModelKind::kTable}, {"analytic", TagErrorModelKind::kAnalytic}},
      o.model.kind);
  o.model.corner_delta_px = node.Get<double>("corner_delta_px", o.model.corner_delta_px);
  o.model.sigma_per_max_error =
      node.Get<double>("sigma_per_max_error", o.model.sigma_per_max_error);
  o.model.corner_sigma_px = node.Get<double>("corner_sigma_px", o.model.corner_sigma_px);
  o.model.tilt_sigma_exponent =
      node.Get<double>("tilt_sigma_exponent", o.model.tilt_sigma_exponent);
  o.model.frontal_sigma_gain = node.Get<double>("frontal_sigma_gain", o.model.frontal_sigma_gain);
  o.model.frontal_tilt_deg = node.Get<double>("frontal_tilt_deg", o.model.frontal_tilt_deg);
  o.model.aligned_edge_sigma_px =
      node.Get<double>("aligned_edge_sigma_px", o.model.aligned_edge_sigma_px);
  o.model.small_tag_side_px = node.Get<double>("small_tag_side_px", o.model.small_tag_side_px);
  o.model.flip_sigma_factor = node.Get<double>("flip_sigma_factor", o.model.flip_sigma_factor);
  o.model.max_tilt_deg = node.Get<double>("max_tilt_deg", o.model.max_tilt_deg);
  o.model.max_reprojection_rmse_px =
      node.Get<double>("max_reprojection_rmse_px", o.model.max_reprojection_rmse_px);
  o.model.max_flipped_fraction =
      node.Get<double>("max_flipped_fraction", o.model.max_flipped_fraction);
  o.model.max_ambiguity_ratio =
      node.Get<double>("max_ambiguity_ratio", o.model.max_ambiguity_ratio);
  if (node.Has("markers")) {
    for (const ConfigNode& item : node.ChildList("markers")) {
      TagMarker m;
      m.id = item.Get<int>("id");
      m.size_m = item.Get<double>("size_m");
      if (item.Has("robot")) {
        m.carrier = TagMarker::Carrier::kRobot;
        m.robot = item.Get<int>("robot");
      } else {
        m.landmark = item.Get<int64_t>("landmark");
      }
      if (item.Has("T_carrier_tag")) {
        m.T_carrier_tag.matrix() = item.Get<Eigen::Matrix4d>("T_carrier_tag");
      }
      o.markers.push_back(m);
    }
  }
  try {
    o.Validate();
  } catch (const std::invalid_argument& e) {
    throw ConfigError(node.Where() + ": " + e.what());
  }
  return o;
}

std::vector<TagErrorTable> LoadTagErrorTables(const TagObserverOptions& options,
                                              const calib::RectifiedIntrinsics& camera,
                                              cv::Size image_size, const std::string& directory,
                                              bool build_missing,
                                              const std::function<void(const std::string&)>& say,
                                              const TagErrorTableSpec& grid) {
  std::vector<TagErrorTable> tables;
  if (options.model.kind != TagErrorModelKind::kTable) return tables;
  const std::string& family = options.detector.families.at(0);
  std::set<int64_t> sizes;
  for (const TagMarker& m : options.markers) {
    if (!sizes.insert(SizeKey(m.size_m)).second) continue;
    const std::string path =
        (std::filesystem::path(directory) / TagErrorTableFileName(family, m.size_m)).string();
    std::string problem;
    try {
      TagErrorTable table = TagErrorTable::Load(path);
      table.CheckMatches(camera, image_size, family, m.size_m);
      if (say) say("tag error table " + path);
      tables.push_back(std::move(table));
      continue;
    } catch (const std::exception& e) {
      problem = e.what();
    }
    if (!build_missing) {
      std::ostringstream command;
      command << problem
              << " (make it with: rover-tags lut --calibration <the board's calibration> "
              << "--family " << family << " --tag-size-m " << m.size_m << " --out " << path << ")";
      throw std::runtime_error(command.str());
    }
    TagErrorTableSpec spec = grid;
    spec.camera = camera;
    spec.image_size = image_size;
    spec.family = family;
    spec.tag_size_m = m.size_m;
    spec.corner_delta_px = options.model.corner_delta_px;
    if (say) say(problem + ": building it");
    const auto start = std::chrono::steady_clock::now();
    TagErrorTable table = TagErrorTable::Build(spec);
    std::filesystem::create_directories(directory);
    table.Save(path);
    if (say) {
      const double s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      say("tag error table " + path + " built in " + std::to_string(static_cast<int>(s)) + " s");
    }
    tables.push_back(std::move(table));
  }
  return tables;
}

TagObserver::TagObserver(const TagObserverOptions& options,
                         const calib::RectifiedIntrinsics& camera, cv::Size image_size,
                         const std::vector<TagErrorTable>& tables)
    : options_(options), camera_(camera), image_size_(image_size), detector_(options.detector) {
  options_.Validate();
  const std::string& family = options_.detector.families[0];
  for (const TagMarker& m : options_.markers) {
    const int64_t key = SizeKey(m.size_m);
    if (models_.count(key)) continue;
    std::optional<TagErrorTable> table;
    for (const TagErrorTable& t : tables) {
      if (SizeKey(t.spec().tag_size_m) != key) continue;
      t.CheckMatches(camera, image_size, family, m.size_m);  // throws what differs
      table = t;
    }
    if (!table && options_.model.kind == TagErrorModelKind::kTable) {
      throw std::invalid_argument("TagObserver: no tag error table for " + family + " " +
                                  SizeText(m.size_m) + " tags (make one with rover-tags lut)");
    }
    models_.emplace(key, TagErrorModel(options_.model, table));
  }
}

std::vector<TagObservation> TagObserver::Observe(const cv::Mat& rectified) {
  if (rectified.size() != image_size_) {
    std::ostringstream s;
    s << "TagObserver::Observe: expected a " << image_size_.width << "x" << image_size_.height
      << " rectified image, found " << rectified.cols << "x" << rectified.rows;
    throw std::invalid_argument(s.str());
  }
  ++stats_.images;
  std::vector<TagRefusal> refused;
  std::vector<TagObservation> out;
  for (const TagDetection& d : detector_.Detect(rectified, &refused)) {
    TagObservation o;
    o.detection = d;
    for (const TagMarker& m : options_.markers) {
      if (m.id == d.id) o.marker = &m;
    }
    if (o.marker == nullptr) {
      o.not_configured = true;
      o.refusal = "tag id " + std::to_string(d.id) + " is not in the configuration";
      ++stats_.not_configured;
      out.push_back(std::move(o));
      continue;
    }
    std::string error;
    o.pose = EstimateTagPose(d.corners_px, o.marker->size_m, camera_, &error);
    if (!o.pose) {
      o.refusal = error;
      ++stats_.no_pose;
      out.push_back(std::move(o));
      continue;
    }
    const TagErrorModel& model = models_.at(SizeKey(o.marker->size_m));
    o.uncertainty = model.Evaluate(d.corners_px, *o.pose, o.marker->size_m, camera_);
    if (o.uncertainty.ambiguous) {
      o.solutions = {model.ForSolution(o.pose->best.T_camera_tag, o.marker->size_m, camera_,
                                       &o.uncertainty.perturbation),
                     model.ForSolution(o.pose->alternative.T_camera_tag, o.marker->size_m, camera_,
                                       &o.uncertainty.perturbation)};
      o.inflated = TagErrorModel::Inflated(*o.pose, o.solutions[0], &o.solutions[1]);
    }
    o.accepted = o.uncertainty.accepted;
    o.refusal = o.uncertainty.refusal;
    (o.accepted ? stats_.accepted : stats_.refused_by_model)++;
    out.push_back(std::move(o));
  }
  stats_.decoded += out.size() + refused.size();
  stats_.refused_by_detector += refused.size();
  for (const TagRefusal& r : refused) {
    TagObservation o;
    o.detection.family = r.family;
    o.detection.id = r.id;
    o.detection.corners_px = r.corners_px;
    o.refusal = r.reason;
    out.push_back(std::move(o));
  }
  return out;
}

log::rover_msgs::TagDetection ToMsg(const TagObservation& o, int64_t stamp_ns,
                                    std::string_view camera_frame) {
  log::rover_msgs::TagDetection m;
  m.header.stamp = log::ToRosTime(Time::FromNanoseconds(stamp_ns));
  m.header.frame_id = log::FrameId::Truncated(camera_frame);
  m.family = o.detection.family;
  m.id = o.detection.id;
  m.accepted = o.accepted;
  m.refusal = o.refusal;
  for (std::size_t k = 0; k < 4; ++k) {
    m.corners_px[2 * k] = o.detection.corners_px[k].x();
    m.corners_px[2 * k + 1] = o.detection.corners_px[k].y();
  }
  m.decision_margin = o.detection.decision_margin;
  m.hamming = o.detection.hamming;
  if (o.pose) {
    m.pose = ToPoseMsg(o.pose->best.T_camera_tag);
    m.alternative_pose = ToPoseMsg(o.pose->alternative.T_camera_tag);
    m.reprojection_rmse_px = o.pose->best.reprojection_rmse_px;
    m.ambiguity_ratio = o.pose->ambiguity_ratio;
    m.distance_m = o.pose->distance_m;
    m.tilt_rad = o.pose->tilt_rad;
  }
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) {
      m.covariance[static_cast<std::size_t>(r * 6 + c)] = o.uncertainty.covariance(r, c);
    }
  }
  m.flipped = static_cast<uint32_t>(o.uncertainty.perturbation.flipped);
  return m;
}

}  // namespace rover::mapping
