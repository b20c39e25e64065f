#ifndef ROVER_MAPPING_LOOP_POINT_KD_TREE_H_
#define ROVER_MAPPING_LOOP_POINT_KD_TREE_H_

// Nearest-neighbour search for the submap matcher, on nanoflann's k-d tree
// (Debian libnanoflann-dev, header only). Two indexes:
//   PointKdTree       3D points (normals, keypoint filtering, ICP);
//   DescriptorIndex   fixed-length descriptors, by k-d tree or brute force
//                     (bench/mapping/loop_match_bench measures both).
// Both own their data, so that they can live inside an immutable
// SubmapMatchData shared between threads: every query is const and
// allocation-free except for the caller's output vectors.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace rover::mapping {

/// One neighbour: index into the indexed points and squared distance.
struct Neighbour {
  uint32_t index = 0;
  float distance_sq = 0.0f;
};

class PointKdTree {
 public:
  /// An empty index.
  PointKdTree();
  /// Indexes `points` (copied). Throws std::invalid_argument naming the first
  /// non-finite point.
  explicit PointKdTree(std::vector<Eigen::Vector3f> points);
  ~PointKdTree();
  PointKdTree(PointKdTree&&) noexcept;
  PointKdTree& operator=(PointKdTree&&) noexcept;
  PointKdTree(const PointKdTree&) = delete;
  PointKdTree& operator=(const PointKdTree&) = delete;

  /// The indexed points, in their original order.
  const std::vector<Eigen::Vector3f>& points() const;
  std::size_t size() const { return points().size(); }

  /// The nearest point to `query`; false if the index is empty or none lies
  /// within `max_distance_m`.
  bool Nearest(const Eigen::Vector3f& query, float max_distance_m, Neighbour* out) const;

  /// Up to `k` nearest points, closest first.
  void Nearest(const Eigen::Vector3f& query, std::size_t k, std::vector<Neighbour>* out) const;

  /// All points within `radius_m` of `query` (unsorted).
  void Radius(const Eigen::Vector3f& query, float radius_m, std::vector<Neighbour>* out) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// How DescriptorIndex searches.
enum class DescriptorSearch {
  kKdTree,      ///< nanoflann, exact
  kBruteForce,  ///< all distances as one matrix product (unit descriptors)
};

class DescriptorIndex {
 public:
  /// An empty index.
  DescriptorIndex();
  /// Indexes the rows of `descriptors` (copied). Throws std::invalid_argument
  /// for a non-finite entry (naming its row).
  DescriptorIndex(const Eigen::MatrixXf& descriptors, DescriptorSearch search);
  ~DescriptorIndex();
  DescriptorIndex(DescriptorIndex&&) noexcept;
  DescriptorIndex& operator=(DescriptorIndex&&) noexcept;
  DescriptorIndex(const DescriptorIndex&) = delete;
  DescriptorIndex& operator=(const DescriptorIndex&) = delete;

  /// The indexed descriptors, one per row.
  const Eigen::MatrixXf& descriptors() const;
  std::size_t size() const;
  DescriptorSearch search() const;

  /// For each row of `queries` (same length as the indexed descriptors),
  /// its `k` nearest indexed descriptors, closest first (fewer if the index
  /// is smaller). Throws std::invalid_argument for a length mismatch.
  std::vector<std::vector<Neighbour>> Nearest(const Eigen::MatrixXf& queries, std::size_t k) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_LOOP_POINT_KD_TREE_H_
