#include "mapping/loop/submap_match_data.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <map>
#include <sstream>
#include <stdexcept>
#include <tuple>
#include <type_traits>

#include "mapping/loop/line_spread.h"
#include "mapping/loop/option_checks.h"
#include "mapping/loop/surface_normals.h"

namespace rover::mapping {
namespace {

// Spill bytes (Serialize/Deserialize): flat values and vectors of them,
// each vector prefixed by its element count. Eigen's fixed-size vectors are
// plain arrays of their scalars, though the standard does not call them
// trivially copyable.
template <typename T>
constexpr bool kFlat = std::is_trivially_copyable_v<T>;
template <>
constexpr bool kFlat<Eigen::Vector3f> = sizeof(Eigen::Vector3f) == 3 * sizeof(float);
template <>
constexpr bool kFlat<Eigen::Vector2d> = sizeof(Eigen::Vector2d) == 2 * sizeof(double);

class SpillWriter {
 public:
  template <typename T>
  void Value(const T& v) {
    static_assert(kFlat<T>);
    out_.append(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  template <typename T>
  void Vector(const std::vector<T>& v) {
    static_assert(kFlat<T>);
    Value(static_cast<uint64_t>(v.size()));
    out_.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
  std::string Take() { return std::move(out_); }

 private:
  std::string out_;
};

class SpillReader {
 public:
  explicit SpillReader(std::string_view bytes) : bytes_(bytes) {}
  template <typename T>
  void Value(const char* field, T* v) {
    static_assert(kFlat<T>);
    Need(field, sizeof(T));
    std::memcpy(static_cast<void*>(v), bytes_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
  }
  template <typename T>
  void Vector(const char* field, std::vector<T>* v) {
    uint64_t n = 0;
    Value(field, &n);
    if (n > (bytes_.size() - pos_) / sizeof(T)) Short(field, n * sizeof(T));
    v->resize(n);
    if (n == 0) return;  // data() may be null, which memcpy must not get
    std::memcpy(static_cast<void*>(v->data()), bytes_.data() + pos_, n * sizeof(T));
    pos_ += n * sizeof(T);
  }
  void ExpectEnd() const {
    if (pos_ != bytes_.size()) {
      throw std::runtime_error(
          "SubmapMatchData::Deserialize: " + std::to_string(bytes_.size() - pos_) +
          " bytes after the last field, expected none");
    }
  }

 private:
  void Need(const char* field, std::size_t n) const {
    if (n > bytes_.size() - pos_) Short(field, n);
  }
  [[noreturn]] void Short(const char* field, uint64_t n) const {
    throw std::runtime_error("SubmapMatchData::Deserialize: " + std::string(field) + " needs " +
                             std::to_string(n) + " bytes at offset " + std::to_string(pos_) +
                             ", found " + std::to_string(bytes_.size() - pos_));
  }
  std::string_view bytes_;
  std::size_t pos_ = 0;
};

constexpr uint32_t kSpillMagic = 0x31444d52;  // "RMD1"

using loop_internal::CheckPositive;
using loop_internal::CheckRange;

enum : uint8_t { kUnknown = 0, kFree = 1, kOccupied = 2 };

// The voxel states of an octree over a box of keys, at full resolution
// (pruned nodes filled over their whole extent).
class DenseVoxels {
 public:
  DenseVoxels(const octomap::OcTree& tree, const octomap::OcTreeKey& lo,
              const octomap::OcTreeKey& hi)
      : lo_(lo) {
    for (unsigned a = 0; a < 3; ++a)
      size_[a] = static_cast<int>(hi[a]) - static_cast<int>(lo[a]) + 1;
    states_.assign(static_cast<std::size_t>(size_[0] * size_[1] * size_[2]), kUnknown);
    const unsigned max_depth = tree.getTreeDepth();
    for (auto it = tree.begin_leafs_bbx(lo, hi), end = tree.end_leafs_bbx(); it != end; ++it) {
      const uint8_t state = tree.isNodeOccupied(*it) ? kOccupied : kFree;
      const int extent = 1 << (max_depth - it.getDepth());
      const octomap::OcTreeKey& key = it.getKey();
      int from[3], to[3];
      for (unsigned a = 0; a < 3; ++a) {
        // A node above the leaf level has the key of its centre, a voxel
        // corner: it spans key - extent / 2 .. key + extent / 2 - 1.
        const int k = static_cast<int>(key[a]);
        const int first = extent == 1 ? k : k - extent / 2;
        from[a] = std::max(first, static_cast<int>(lo[a])) - static_cast<int>(lo[a]);
        to[a] = std::min(first + extent - 1, static_cast<int>(hi[a])) - static_cast<int>(lo[a]);
      }
      for (int z = from[2]; z <= to[2]; ++z) {
        for (int y = from[1]; y <= to[1]; ++y) {
          for (int x = from[0]; x <= to[0]; ++x) states_[Index(x, y, z)] = state;
        }
      }
    }
  }

  /// State at box coordinates, unknown outside the box (a query's sphere
  /// and the column above it may reach a voxel past the box's edge).
  uint8_t At(int x, int y, int z) const {
    if (x < 0 || y < 0 || z < 0 || x >= size_[0] || y >= size_[1] || z >= size_[2]) {
      return kUnknown;
    }
    return states_[Index(x, y, z)];
  }
  /// State at a key, unknown outside the box.
  uint8_t AtKey(const octomap::OcTreeKey& k) const {
    return At(static_cast<int>(k[0]) - static_cast<int>(lo_[0]),
              static_cast<int>(k[1]) - static_cast<int>(lo_[1]),
              static_cast<int>(k[2]) - static_cast<int>(lo_[2]));
  }
  const int* size() const { return size_; }
  const octomap::OcTreeKey& lo() const { return lo_; }

 private:
  std::size_t Index(int x, int y, int z) const {
    return static_cast<std::size_t>((z * size_[1] + y) * size_[0] + x);
  }
  octomap::OcTreeKey lo_;
  int size_[3] = {0, 0, 0};
  std::vector<uint8_t> states_;
};

double MsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

void SubmapMatchDataOptions::Validate() const {
  constexpr const char* kC = "SubmapMatchDataOptions";
  CheckPositive(kC, "keypoint_voxel_m", keypoint_voxel_m);
  CheckRange(kC, "min_known_ratio", min_known_ratio, 0.0, 1.0);
  CheckPositive(kC, "normal_radius_m", normal_radius_m);
  CheckRange(kC, "min_points", min_points, 0, 1e9);
  CheckRange(kC, "min_obstacle_points", min_obstacle_points, 0, 1e9);
  CheckPositive(kC, "off_line_distance_m", off_line_distance_m);
  CheckRange(kC, "min_keypoints_off_line", min_keypoints_off_line, 0, 1e9);
  CheckRange(kC, "line_samples", line_samples, 1, 1e9);
  CheckPositive(kC, "icp_voxel_m", icp_voxel_m);
  descriptor.Validate();
}

SubmapMatchDataOptions SubmapMatchDataOptions::Load(const ConfigNode& node) {
  SubmapMatchDataOptions o;
  o.keypoint_voxel_m = node.Get<double>("keypoint_voxel_m", o.keypoint_voxel_m);
  o.min_known_ratio = node.Get<double>("min_known_ratio", o.min_known_ratio);
  o.solid_below_surface = node.Get<bool>("solid_below_surface", o.solid_below_surface);
  o.normal_radius_m = node.Get<double>("normal_radius_m", o.normal_radius_m);
  o.orient_normals_to_free_space =
      node.Get<bool>("orient_normals_to_free_space", o.orient_normals_to_free_space);
  o.min_points = node.Get<int>("min_points", o.min_points);
  o.min_obstacle_points = node.Get<int>("min_obstacle_points", o.min_obstacle_points);
  o.off_line_distance_m = node.Get<double>("off_line_distance_m", o.off_line_distance_m);
  o.min_keypoints_off_line = node.Get<int>("min_keypoints_off_line", o.min_keypoints_off_line);
  o.line_samples = node.Get<int>("line_samples", o.line_samples);
  o.icp_voxel_m = node.Get<double>("icp_voxel_m", o.icp_voxel_m);
  if (node.Has("descriptor"))
    o.descriptor = GravityDescriptorOptions::Load(node.Child("descriptor"));
  o.descriptor_search = node.GetEnum<DescriptorSearch>(
      "descriptor_search",
      {{"kdtree", DescriptorSearch::kKdTree}, {"brute_force", DescriptorSearch::kBruteForce}},
      o.descriptor_search);
  o.seed = node.Get<uint64_t>("seed", o.seed);
  o.Validate();
  return o;
}

const char* ToString(SubmapSuitability s) {
  switch (s) {
    case SubmapSuitability::kSuitable:
      return "suitable";
    case SubmapSuitability::kTooFewPoints:
      return "too few points";
    case SubmapSuitability::kTooFewObstaclePoints:
      return "too few obstacle points";
    case SubmapSuitability::kKeypointsOnALine:
      return "keypoints on a line";
  }
  return "?";
}

std::vector<Eigen::Vector3f> VoxelCentroids(const std::vector<Eigen::Vector3f>& points,
                                            double voxel_m) {
  // std::map keeps the voxels sorted: the output order is the voxel order.
  std::map<std::tuple<int64_t, int64_t, int64_t>, std::pair<Eigen::Vector3d, int>> voxels;
  for (const Eigen::Vector3f& pf : points) {
    const Eigen::Vector3d p = pf.cast<double>();
    const auto key = std::make_tuple(static_cast<int64_t>(std::floor(p.z() / voxel_m)),
                                     static_cast<int64_t>(std::floor(p.y() / voxel_m)),
                                     static_cast<int64_t>(std::floor(p.x() / voxel_m)));
    auto& [sum, count] = voxels[key];
    if (count == 0) sum.setZero();
    sum += p;
    ++count;
  }
  std::vector<Eigen::Vector3f> out;
  out.reserve(voxels.size());
  for (const auto& [key, v] : voxels) out.push_back((v.first / v.second).cast<float>());
  return out;
}

void OrientNormalsToFreeSpace(const octomap::OcTree& octree,
                              const std::vector<Eigen::Vector3f>& points,
                              std::vector<Eigen::Vector3f>* normals) {
  if (points.empty()) return;
  const auto step = static_cast<float>(octree.getResolution());
  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f& p : points) box.extend(p);
  octomap::OcTreeKey lo, hi;
  const Eigen::Vector3f min = box.min().array() - 2.0f * step;
  const Eigen::Vector3f max = box.max().array() + 2.0f * step;
  if (!octree.coordToKeyChecked(min.x(), min.y(), min.z(), lo) ||
      !octree.coordToKeyChecked(max.x(), max.y(), max.z(), hi)) {
    return;  // beyond the key range: keep the gravity orientation
  }
  const DenseVoxels voxels(octree, lo, hi);
  const auto state = [&](const Eigen::Vector3f& p) {
    return voxels.AtKey(octree.coordToKey(p.x(), p.y(), p.z()));
  };
  for (std::size_t i = 0; i < points.size(); ++i) {
    Eigen::Vector3f& n = (*normals)[i];
    if (state(points[i] + step * n) != kFree && state(points[i] - step * n) == kFree) n = -n;
  }
}

std::vector<float> KnownRatios(const octomap::OcTree& octree,
                               const std::vector<Eigen::Vector3f>& queries, double radius_m,
                               bool solid_below_surface) {
  std::vector<float> ratios(queries.size(), 0.0f);
  if (queries.empty()) return ratios;
  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f& q : queries) box.extend(q);
  const auto r = static_cast<float>(radius_m);
  octomap::OcTreeKey lo, hi;
  const Eigen::Vector3f min = box.min().array() - r;
  const Eigen::Vector3f max = box.max().array() + r;
  if (!octree.coordToKeyChecked(min.x(), min.y(), min.z(), lo) ||
      !octree.coordToKeyChecked(max.x(), max.y(), max.z(), hi)) {
    throw std::invalid_argument("KnownRatios: keypoints beyond the octree's key range");
  }
  const DenseVoxels voxels(octree, lo, hi);
  const double res = octree.getResolution();
  const int reach = static_cast<int>(std::ceil(radius_m / res)) + 1;
  for (std::size_t q = 0; q < queries.size(); ++q) {
    const octomap::OcTreeKey k = octree.coordToKey(queries[q].x(), queries[q].y(), queries[q].z());
    const octomap::point3d c = octree.keyToCoord(k);
    // Offset of the query from its voxel centre, in voxels.
    const Eigen::Vector3d off =
        (queries[q] - Eigen::Vector3f(c.x(), c.y(), c.z())).cast<double>() / res;
    const double r_vox_sq = (radius_m / res) * (radius_m / res);
    int known = 0;
    int total = 0;
    for (int dy = -reach; dy <= reach; ++dy) {
      for (int dx = -reach; dx <= reach; ++dx) {
        const double h_sq = (dx - off.x()) * (dx - off.x()) + (dy - off.y()) * (dy - off.y());
        if (h_sq > r_vox_sq) continue;
        const int x = static_cast<int>(k[0]) - static_cast<int>(lo[0]) + dx;
        const int y = static_cast<int>(k[1]) - static_cast<int>(lo[1]) + dy;
        // Top down through the column, so that "below a surface" is known
        // when an unknown voxel is reached.
        bool under_surface = false;
        for (int dz = reach; dz >= -reach; --dz) {
          const double d_sq = h_sq + (dz - off.z()) * (dz - off.z());
          const int z = static_cast<int>(k[2]) - static_cast<int>(lo[2]) + dz;
          if (d_sq > r_vox_sq) {
            // Above the sphere an occupied voxel still covers the column.
            if (dz > 0 && voxels.At(x, y, z) == kOccupied) under_surface = true;
            continue;
          }
          ++total;
          const uint8_t s = voxels.At(x, y, z);
          if (s == kOccupied) under_surface = true;
          if (s != kUnknown || (solid_below_surface && under_surface)) ++known;
        }
      }
    }
    ratios[q] = total > 0 ? static_cast<float>(known) / static_cast<float>(total) : 0.0f;
  }
  return ratios;
}

SubmapMatchData::SubmapMatchData(const PointCloud& cloud, const octomap::OcTree& octree,
                                 const SubmapMatchDataOptions& options)
    : options_(options) {
  const auto t0 = std::chrono::steady_clock::now();
  options_.Validate();
  std::vector<Eigen::Vector3f> points;
  std::vector<Eigen::Vector3f> obstacle_points;
  points.reserve(cloud.size());
  obstacle_.reserve(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (!cloud[i].p_submap_m.allFinite()) {
      throw std::invalid_argument("SubmapMatchData: cloud point " + std::to_string(i) +
                                  " is not finite (expected finite coordinates)");
    }
    points.push_back(cloud[i].p_submap_m);
    obstacle_.push_back(cloud[i].obstacle ? 1 : 0);
    if (cloud[i].obstacle) {
      obstacle_points.push_back(cloud[i].p_submap_m);
      obstacle_box_xy_.extend(cloud[i].p_submap_m.head<2>().cast<double>());
    }
  }
  obstacle_points_ = static_cast<int>(obstacle_points.size());
  cloud_ = PointKdTree(std::move(points));
  const std::vector<Eigen::Vector3f>& pts = cloud_.points();

  std::ostringstream why;
  if (point_count() < options_.min_points) {
    suitability_ = SubmapSuitability::kTooFewPoints;
    why << point_count() << " points, expected >= " << options_.min_points;
  } else if (obstacle_points_ < options_.min_obstacle_points) {
    suitability_ = SubmapSuitability::kTooFewObstaclePoints;
    why << obstacle_points_ << " obstacle points, expected >= " << options_.min_obstacle_points;
  }
  if (!suitable()) {
    reason_ = std::string(ToString(suitability_)) + ": " + why.str();
    build_ms_ = MsSince(t0);
    return;
  }

  normals_ = ComputeSurfaceNormals(cloud_, static_cast<float>(options_.normal_radius_m));
  if (options_.orient_normals_to_free_space) OrientNormalsToFreeSpace(octree, pts, &normals_);
  icp_points_ = VoxelCentroids(pts, options_.icp_voxel_m);
  icp_normals_.reserve(icp_points_.size());
  for (const Eigen::Vector3f& p : icp_points_) {
    Neighbour n;
    cloud_.Nearest(p, static_cast<float>(options_.icp_voxel_m), &n);
    icp_normals_.push_back(normals_[n.index]);
    icp_obstacle_.push_back(obstacle_[n.index]);
  }

  std::vector<Eigen::Vector3f> candidates =
      VoxelCentroids(obstacle_points, options_.keypoint_voxel_m);
  keypoints_before_filter_ = static_cast<int>(candidates.size());
  if (options_.min_known_ratio > 0.0) {
    const std::vector<float> ratios =
        KnownRatios(octree, candidates, options_.descriptor.radius_m, options_.solid_below_surface);
    std::vector<Eigen::Vector3f> kept;
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      if (static_cast<double>(ratios[i]) >= options_.min_known_ratio) kept.push_back(candidates[i]);
    }
    keypoints_dropped_unknown_ = static_cast<int>(candidates.size() - kept.size());
    candidates = std::move(kept);
  }
  const KeypointDescriptors d =
      ComputeGravityDescriptors(cloud_, normals_, candidates, options_.descriptor);
  Eigen::MatrixXf rows(static_cast<Eigen::Index>(candidates.size()), d.descriptors.cols());
  Eigen::Index kept = 0;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    if (!d.valid[i]) continue;
    keypoints_.push_back(candidates[i]);
    yaw_reference_rad_.push_back(d.yaw_reference_rad[i]);
    yaw_reference_strength_.push_back(d.yaw_reference_strength[i]);
    rows.row(kept++) = d.descriptors.row(static_cast<Eigen::Index>(i));
  }
  keypoints_dropped_support_ = static_cast<int>(candidates.size()) - static_cast<int>(kept);
  descriptors_ = DescriptorIndex(rows.topRows(kept), options_.descriptor_search);

  keypoints_off_line_ =
      CountOffLine(keypoints_, options_.off_line_distance_m, options_.line_samples, options_.seed);
  if (keypoints_off_line_ < options_.min_keypoints_off_line) {
    suitability_ = SubmapSuitability::kKeypointsOnALine;
    why << keypoints_off_line_ << " of " << keypoints_.size() << " keypoints farther than "
        << options_.off_line_distance_m
        << " m from the best line, expected >= " << options_.min_keypoints_off_line;
    reason_ = std::string(ToString(suitability_)) + ": " + why.str();
  } else {
    why << pts.size() << " points, " << obstacle_points_ << " obstacle points, "
        << keypoints_.size() << " keypoints (" << keypoints_dropped_unknown_
        << " dropped near unknown space), " << keypoints_off_line_ << " off the best line";
    reason_ = "suitable: " + why.str();
  }
  build_ms_ = MsSince(t0);
}

std::string SubmapMatchData::Serialize() const {
  SpillWriter w;
  w.Value(kSpillMagic);
  w.Value(static_cast<int32_t>(suitability_));
  w.Vector(std::vector<char>(reason_.begin(), reason_.end()));
  w.Vector(keypoints_);
  const Eigen::MatrixXf& d = descriptors_.descriptors();
  w.Value(static_cast<int64_t>(d.rows()));
  w.Value(static_cast<int64_t>(d.cols()));
  w.Vector(std::vector<float>(d.data(), d.data() + d.size()));
  w.Vector(yaw_reference_rad_);
  w.Vector(yaw_reference_strength_);
  w.Vector(cloud_.points());
  w.Vector(normals_);
  w.Vector(obstacle_);
  w.Vector(icp_points_);
  w.Vector(icp_normals_);
  w.Vector(icp_obstacle_);
  w.Value(obstacle_box_xy_.min().eval());
  w.Value(obstacle_box_xy_.max().eval());
  for (const int count : {obstacle_points_, keypoints_before_filter_, keypoints_dropped_unknown_,
                          keypoints_dropped_support_, keypoints_off_line_}) {
    w.Value(static_cast<int32_t>(count));
  }
  w.Value(build_ms_);
  return w.Take();
}

std::shared_ptr<const SubmapMatchData> SubmapMatchData::Deserialize(
    std::string_view bytes, const SubmapMatchDataOptions& options) {
  std::shared_ptr<SubmapMatchData> data(new SubmapMatchData());
  SubmapMatchData& m = *data;
  m.options_ = options;
  SpillReader r(bytes);
  uint32_t magic = 0;
  r.Value("magic", &magic);
  if (magic != kSpillMagic) {
    throw std::runtime_error("SubmapMatchData::Deserialize: not match data (bad magic number)");
  }
  int32_t suitability = 0;
  r.Value("suitability", &suitability);
  if (suitability < 0 || suitability > static_cast<int32_t>(SubmapSuitability::kKeypointsOnALine)) {
    throw std::runtime_error("SubmapMatchData::Deserialize: suitability " +
                             std::to_string(suitability) + " is not one of the enum's");
  }
  m.suitability_ = static_cast<SubmapSuitability>(suitability);
  std::vector<char> reason;
  r.Vector("reason", &reason);
  m.reason_.assign(reason.begin(), reason.end());
  r.Vector("keypoints", &m.keypoints_);
  int64_t rows = 0;
  int64_t cols = 0;
  r.Value("descriptor rows", &rows);
  r.Value("descriptor cols", &cols);
  std::vector<float> values;
  r.Vector("descriptors", &values);
  if (rows < 0 || cols < 0 ||
      static_cast<uint64_t>(rows) * static_cast<uint64_t>(cols) != values.size()) {
    throw std::runtime_error("SubmapMatchData::Deserialize: " + std::to_string(values.size()) +
                             " descriptor values for " + std::to_string(rows) + " x " +
                             std::to_string(cols));
  }
  r.Vector("yaw references", &m.yaw_reference_rad_);
  r.Vector("yaw strengths", &m.yaw_reference_strength_);
  std::vector<Eigen::Vector3f> points;
  r.Vector("cloud", &points);
  r.Vector("normals", &m.normals_);
  r.Vector("obstacle flags", &m.obstacle_);
  r.Vector("ICP points", &m.icp_points_);
  r.Vector("ICP normals", &m.icp_normals_);
  r.Vector("ICP obstacle flags", &m.icp_obstacle_);
  Eigen::Vector2d box_min;
  Eigen::Vector2d box_max;
  r.Value("box min", &box_min);
  r.Value("box max", &box_max);
  m.obstacle_box_xy_ = Eigen::AlignedBox2d(box_min, box_max);
  for (int* count :
       {&m.obstacle_points_, &m.keypoints_before_filter_, &m.keypoints_dropped_unknown_,
        &m.keypoints_dropped_support_, &m.keypoints_off_line_}) {
    int32_t value = 0;
    r.Value("counts", &value);
    *count = value;
  }
  r.Value("build time", &m.build_ms_);
  r.ExpectEnd();
  const std::size_t n = points.size();
  const bool consistent = m.obstacle_.size() == n &&
                          (m.normals_.empty() || m.normals_.size() == n) &&
                          m.icp_normals_.size() == m.icp_points_.size() &&
                          m.icp_obstacle_.size() == m.icp_points_.size() &&
                          m.yaw_reference_rad_.size() == m.keypoints_.size() &&
                          m.yaw_reference_strength_.size() == m.keypoints_.size() &&
                          (rows == 0 || static_cast<std::size_t>(rows) == m.keypoints_.size());
  if (!consistent) {
    throw std::runtime_error("SubmapMatchData::Deserialize: field sizes disagree (" +
                             std::to_string(n) + " points, " + std::to_string(m.obstacle_.size()) +
                             " obstacle flags, " + std::to_string(m.normals_.size()) +
                             " normals, " + std::to_string(m.keypoints_.size()) + " keypoints, " +
                             std::to_string(rows) + " descriptors)");
  }
  m.cloud_ = PointKdTree(std::move(points));
  if (rows > 0 || cols > 0) {
    m.descriptors_ = DescriptorIndex(Eigen::Map<const Eigen::MatrixXf>(values.data(), rows, cols),
                                     options.descriptor_search);
  }
  return data;
}

std::shared_ptr<const SubmapMatchData> SubmapMatchData::Build(
    const PointCloud& cloud, const octomap::OcTree& octree, const SubmapMatchDataOptions& options) {
  return std::make_shared<const SubmapMatchData>(cloud, octree, options);
}

}  // namespace rover::mapping
