#include "mapping/tags/tag_error_table.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "core/config/config.h"
#include "mapping/loop/option_checks.h"
#include "mapping/tags/tag_detector.h"
#include "mapping/tags/tag_pattern.h"
#include "mapping/tags/tag_pose.h"

namespace rover::mapping {
namespace {

using loop_internal::CheckPositive;
using loop_internal::CheckRange;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Pixels kept around the printed tag (its white margin included) when only
// the part of the image around it is rendered.
constexpr int kRoiMarginPx = 8;

Eigen::Isometry3d TagOnAxis(double distance_m, double tilt_rad) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(tilt_rad, Eigen::Vector3d::UnitY()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.0, 0.0, distance_m);
  return T;
}

// The errors of the best of both solutions against the truth: the flip is
// the online step's business, the table models the rest (as the thesis
// compensates large rotational errors given the truth).
std::optional<TagPoseErrors> ClosestSolutionError(const std::array<Eigen::Vector2d, 4>& corners,
                                                  const TagErrorTableSpec& spec,
                                                  const Eigen::Isometry3d& truth) {
  std::string error;
  const std::optional<TagPose> pose =
      EstimateTagPose(corners, spec.tag_size_m, spec.camera, &error);
  if (!pose) return std::nullopt;
  const TagPoseErrors a = TagPoseError(pose->best.T_camera_tag, truth);
  const TagPoseErrors b = TagPoseError(pose->alternative.T_camera_tag, truth);
  return a.tail<3>().norm() <= b.tail<3>().norm() ? a : b;
}

// One cell: NaN where the tag is cut by the image or not detected.
TagPoseErrors BuildCell(const TagErrorTableSpec& spec, const TagPattern& pattern,
                        TagDetector* detector, double distance_m, double tilt_rad) {
  TagPoseErrors cell = TagPoseErrors::Constant(kNaN);
  const Eigen::Isometry3d truth = TagOnAxis(distance_m, tilt_rad);
  // The printed square with its margin, projected: the part of the image to render.
  const double half = 0.5 * spec.tag_size_m * pattern.cells_per_side / pattern.border_cells;
  double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
  for (const double sx : {-1.0, 1.0}) {
    for (const double sy : {-1.0, 1.0}) {
      const Eigen::Vector3d p = truth * Eigen::Vector3d(sx * half, sy * half, 0.0);
      if (p.z() <= 0.0) return cell;
      const double u = spec.camera.fx * p.x() / p.z() + spec.camera.cx;
      const double v = spec.camera.fy * p.y() / p.z() + spec.camera.cy;
      x0 = std::min(x0, u), x1 = std::max(x1, u), y0 = std::min(y0, v), y1 = std::max(y1, v);
    }
  }
  const int left = static_cast<int>(std::floor(x0)) - kRoiMarginPx;
  const int top = static_cast<int>(std::floor(y0)) - kRoiMarginPx;
  const int right = static_cast<int>(std::ceil(x1)) + kRoiMarginPx;
  const int bottom = static_cast<int>(std::ceil(y1)) + kRoiMarginPx;
  if (left < 0 || top < 0 || right >= spec.image_size.width || bottom >= spec.image_size.height) {
    return cell;  // not wholly in the image
  }
  calib::RectifiedIntrinsics roi_camera = spec.camera;
  roi_camera.cx -= left;
  roi_camera.cy -= top;
  const cv::Mat image = RenderTagImage(pattern, spec.tag_size_m, truth, roi_camera,
                                       cv::Size(right - left + 1, bottom - top + 1), spec.render);
  const std::vector<TagDetection> found = detector->Detect(image);
  if (found.size() != 1 || found[0].id != spec.tag_id) return cell;
  std::array<Eigen::Vector2d, 4> corners = found[0].corners_px;
  for (Eigen::Vector2d& c : corners) c += Eigen::Vector2d(left, top);
  TagPoseErrors worst = TagPoseErrors::Zero();
  bool any = false;
  for (unsigned signs = 0; signs <= 256; ++signs) {  // 256: unperturbed
    const std::optional<TagPoseErrors> e = ClosestSolutionError(
        signs < 256 ? PerturbedCorners(corners, spec.corner_delta_px, signs) : corners, spec,
        truth);
    if (!e) continue;
    worst = worst.cwiseMax(e->cwiseAbs());
    any = true;
  }
  return any ? worst : cell;
}

double Median(std::vector<double>* v) {
  std::sort(v->begin(), v->end());
  const std::size_t n = v->size();
  return n % 2 ? (*v)[n / 2] : 0.5 * ((*v)[n / 2 - 1] + (*v)[n / 2]);
}

}  // namespace

std::string TagErrorTableFileName(const std::string& family, double tag_size_m) {
  return "tag_errors_" + family + "_" + std::to_string(std::llround(tag_size_m * 1000.0)) +
         "mm.yaml";
}

void TagErrorTableSpec::Validate() const {
  constexpr const char* kName = "TagErrorTableSpec";
  CheckPositive(kName, "camera.fx", camera.fx);
  CheckPositive(kName, "camera.fy", camera.fy);
  CheckRange(kName, "image_size.width", image_size.width, 16, 100000);
  CheckRange(kName, "image_size.height", image_size.height, 16, 100000);
  CheckPositive(kName, "tag_size_m", tag_size_m);
  CheckRange(kName, "corner_delta_px", corner_delta_px, 0.0, 10.0);
  CheckPositive(kName, "min_distance_m", min_distance_m);
  CheckRange(kName, "max_distance_m", max_distance_m, min_distance_m, 1000.0);
  CheckRange(kName, "distance_steps", distance_steps, 2, 2000);
  CheckRange(kName, "max_tilt_rad", max_tilt_rad, 0.01, 1.56);
  CheckRange(kName, "tilt_steps", tilt_steps, 2, 2000);
  render.Validate();
  (void)MakeTagPattern(family, tag_id);  // throws for an unknown family or id
}

TagErrorTable::TagErrorTable(const TagErrorTableSpec& spec) : spec_(spec) {
  spec_.Validate();
  cells_.assign(static_cast<std::size_t>(spec_.distance_steps * spec_.tilt_steps),
                TagPoseErrors::Constant(kNaN));
}

double TagErrorTable::Distance(int i) const {
  return spec_.min_distance_m +
         (spec_.max_distance_m - spec_.min_distance_m) * i / (spec_.distance_steps - 1);
}

double TagErrorTable::Tilt(int j) const {
  return -spec_.max_tilt_rad + 2.0 * spec_.max_tilt_rad * j / (spec_.tilt_steps - 1);
}

const TagPoseErrors& TagErrorTable::At(int i, int j) const {
  return cells_[static_cast<std::size_t>(i * spec_.tilt_steps + j)];
}

TagPoseErrors& TagErrorTable::At(int i, int j) {
  return cells_[static_cast<std::size_t>(i * spec_.tilt_steps + j)];
}

TagErrorTable TagErrorTable::Build(const TagErrorTableSpec& spec,
                                   const std::function<void(std::size_t, std::size_t)>& progress) {
  TagErrorTable table(spec);
  const TagPattern pattern = MakeTagPattern(spec.family, spec.tag_id);
  TagDetectorOptions detector_options;
  detector_options.families = {spec.family};
  TagDetector detector(detector_options);
  const std::size_t total = table.cells_.size();
  std::size_t done = 0;
  for (int i = 0; i < spec.distance_steps; ++i) {
    for (int j = 0; j < spec.tilt_steps; ++j) {
      table.At(i, j) = BuildCell(spec, pattern, &detector, table.Distance(i), table.Tilt(j));
      if (!std::isnan(table.At(i, j)[0])) ++table.detected_cells_;
      if (progress) progress(++done, total);
    }
  }
  table.PostProcess();
  return table;
}

void TagErrorTable::PostProcess() {
  const int nd = spec_.distance_steps;
  const int nt = spec_.tilt_steps;
  // 3x3 median over the detected neighbours of each detected cell.
  std::vector<TagPoseErrors> filtered = cells_;
  for (int i = 0; i < nd; ++i) {
    for (int j = 0; j < nt; ++j) {
      if (std::isnan(At(i, j)[0])) continue;
      for (int k = 0; k < 6; ++k) {
        std::vector<double> v;
        for (int di = -1; di <= 1; ++di) {
          for (int dj = -1; dj <= 1; ++dj) {
            const int a = i + di, b = j + dj;
            if (a < 0 || b < 0 || a >= nd || b >= nt || std::isnan(At(a, b)[0])) continue;
            v.push_back(At(a, b)[k]);
          }
        }
        filtered[static_cast<std::size_t>(i * nt + j)][k] = Median(&v);
      }
    }
  }
  cells_ = filtered;
  // Each distance row: beyond its valid region, the value at its border.
  for (int i = 0; i < nd; ++i) {
    int first = -1, last = -1;
    for (int j = 0; j < nt; ++j) {
      if (std::isnan(At(i, j)[0])) continue;
      if (first < 0) first = j;
      last = j;
    }
    if (first < 0) continue;
    for (int j = 0; j < first; ++j) At(i, j) = At(i, first);
    for (int j = last + 1; j < nt; ++j) At(i, j) = At(i, last);
    for (int j = first + 1; j < last; ++j) {  // holes inside: the larger neighbour's
      if (!std::isnan(At(i, j)[0])) continue;
      const TagPoseErrors& next = At(i, j + 1);  // NaN while the hole goes on
      At(i, j) = std::isnan(next[0]) ? At(i, j - 1) : At(i, j - 1).cwiseMax(next);
    }
  }
  // Each tilt column: the rest with the maximum of the last 10 % of its
  // valid values (the farthest detections).
  for (int j = 0; j < nt; ++j) {
    std::vector<int> valid;
    for (int i = 0; i < nd; ++i) {
      if (!std::isnan(At(i, j)[0])) valid.push_back(i);
    }
    if (valid.empty()) continue;
    const std::size_t tail = std::max<std::size_t>(1, valid.size() / 10);
    TagPoseErrors fill = TagPoseErrors::Zero();
    for (std::size_t k = valid.size() - tail; k < valid.size(); ++k) {
      fill = fill.cwiseMax(At(valid[k], j));
    }
    for (int i = 0; i < nd; ++i) {
      if (std::isnan(At(i, j)[0])) At(i, j) = fill;
    }
  }
}

TagPoseErrors TagErrorTable::Lookup(double distance_m, double tilt_rad) const {
  const auto index = [](double x, double lo, double hi, int n, int* i0, double* f) {
    const double t = std::clamp((x - lo) / (hi - lo), 0.0, 1.0) * (n - 1);
    *i0 = std::min(static_cast<int>(std::floor(t)), n - 2);
    *f = t - *i0;
  };
  int i = 0, j = 0;
  double fi = 0.0, fj = 0.0;
  index(distance_m, spec_.min_distance_m, spec_.max_distance_m, spec_.distance_steps, &i, &fi);
  index(tilt_rad, -spec_.max_tilt_rad, spec_.max_tilt_rad, spec_.tilt_steps, &j, &fj);
  return (1 - fi) * ((1 - fj) * At(i, j) + fj * At(i, j + 1)) +
         fi * ((1 - fj) * At(i + 1, j) + fj * At(i + 1, j + 1));
}

void TagErrorTable::CheckMatches(const calib::RectifiedIntrinsics& camera, cv::Size image_size,
                                 const std::string& family, double tag_size_m) const {
  std::ostringstream why;
  const calib::RectifiedIntrinsics& c = spec_.camera;
  if (image_size != spec_.image_size) {
    why << "image " << image_size.width << "x" << image_size.height << ", table for "
        << spec_.image_size.width << "x" << spec_.image_size.height;
  } else if (std::abs(camera.fx - c.fx) > 0.5 || std::abs(camera.fy - c.fy) > 0.5 ||
             std::abs(camera.cx - c.cx) > 0.5 || std::abs(camera.cy - c.cy) > 0.5) {
    why << "intrinsics fx " << camera.fx << " fy " << camera.fy << " cx " << camera.cx << " cy "
        << camera.cy << ", table for fx " << c.fx << " fy " << c.fy << " cx " << c.cx << " cy "
        << c.cy;
  } else if (family != spec_.family) {
    why << "family " << family << ", table for " << spec_.family;
  } else if (std::abs(tag_size_m - spec_.tag_size_m) > 1e-4) {
    why << "tag size " << tag_size_m << " m, table for " << spec_.tag_size_m << " m";
  }
  if (!why.str().empty()) {
    throw std::invalid_argument("tag error table made for another camera or tag: " + why.str());
  }
}

void TagErrorTable::Save(const std::string& path) const {
  std::ofstream out(path);
  out.precision(9);
  const calib::RectifiedIntrinsics& c = spec_.camera;
  out << "# Maximum tag pose errors over distance and tilt (thesis 6.2.3).\n"
      << "# errors: per cell (distance-major, then tilt), 6 values: dx dy dz [m, camera]\n"
      << "# droll dpitch dyaw [rad, tag frame], after post-processing.\n"
      << "format: rover_tag_error_table\nversion: 1\n"
      << "camera: {width: " << spec_.image_size.width << ", height: " << spec_.image_size.height
      << ", fx: " << c.fx << ", fy: " << c.fy << ", cx: " << c.cx << ", cy: " << c.cy << "}\n"
      << "family: " << spec_.family << "\ntag_id: " << spec_.tag_id
      << "\ntag_size_m: " << spec_.tag_size_m << "\ncorner_delta_px: " << spec_.corner_delta_px
      << "\ndistance_m: {min: " << spec_.min_distance_m << ", max: " << spec_.max_distance_m
      << ", steps: " << spec_.distance_steps << "}\ntilt_rad: {max: " << spec_.max_tilt_rad
      << ", steps: " << spec_.tilt_steps << "}\ndetected_cells: " << detected_cells_
      << "\nerrors: [";
  for (std::size_t k = 0; k < cells_.size(); ++k) {
    for (int d = 0; d < 6; ++d) out << (k || d ? ", " : "") << cells_[k][d];
  }
  out << "]\n";
  if (!out) throw std::runtime_error(path + ": cannot write the tag error table");
}

TagErrorTable TagErrorTable::Load(const std::string& path) {
  try {
    const ConfigNode root = ConfigNode::LoadFile(path);
    if (root.Get<std::string>("format") != "rover_tag_error_table") {
      throw std::runtime_error(path + ": expected format rover_tag_error_table");
    }
    if (root.Get<int>("version") != 1) throw std::runtime_error(path + ": expected version 1");
    TagErrorTableSpec spec;
    const ConfigNode camera = root.Child("camera");
    spec.image_size = cv::Size(camera.Get<int>("width"), camera.Get<int>("height"));
    spec.camera.fx = camera.Get<double>("fx");
    spec.camera.fy = camera.Get<double>("fy");
    spec.camera.cx = camera.Get<double>("cx");
    spec.camera.cy = camera.Get<double>("cy");
    spec.family = root.Get<std::string>("family");
    spec.tag_id = root.Get<int>("tag_id");
    spec.tag_size_m = root.Get<double>("tag_size_m");
    spec.corner_delta_px = root.Get<double>("corner_delta_px");
    const ConfigNode d = root.Child("distance_m");
    spec.min_distance_m = d.Get<double>("min");
    spec.max_distance_m = d.Get<double>("max");
    spec.distance_steps = d.Get<int>("steps");
    const ConfigNode t = root.Child("tilt_rad");
    spec.max_tilt_rad = t.Get<double>("max");
    spec.tilt_steps = t.Get<int>("steps");
    TagErrorTable table(spec);
    table.detected_cells_ = root.Get<std::size_t>("detected_cells");
    const std::vector<double> errors = root.Get<std::vector<double>>("errors");
    if (errors.size() != table.cells_.size() * 6) {
      throw std::runtime_error(
          path + ": errors: expected " + std::to_string(table.cells_.size() * 6) + " values (" +
          std::to_string(spec.distance_steps) + " x " + std::to_string(spec.tilt_steps) +
          " cells x 6), found " + std::to_string(errors.size()));
    }
    for (std::size_t k = 0; k < table.cells_.size(); ++k) {
      for (int e = 0; e < 6; ++e) table.cells_[k][e] = errors[k * 6 + static_cast<std::size_t>(e)];
    }
    return table;
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
}

}  // namespace rover::mapping
