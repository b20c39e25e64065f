#include "mapping/loop/point_kd_tree.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <nanoflann.hpp>

namespace rover::mapping {
namespace {

// nanoflann's dataset interface over the owned points.
struct PointSource {
  std::vector<Eigen::Vector3f> points;
  std::size_t kdtree_get_point_count() const { return points.size(); }
  float kdtree_get_pt(uint32_t i, std::size_t dim) const {
    return points[i][static_cast<Eigen::Index>(dim)];
  }
  template <class BBox>
  bool kdtree_get_bbox(BBox&) const {
    return false;
  }
};

using PointTree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, PointSource, float>,
                                        PointSource, 3, uint32_t>;

// Row-major copy of the descriptors, so that one descriptor is contiguous.
struct DescriptorSource {
  std::vector<float> data;
  std::size_t rows = 0;
  std::size_t cols = 0;
  std::size_t kdtree_get_point_count() const { return rows; }
  float kdtree_get_pt(uint32_t i, std::size_t dim) const { return data[i * cols + dim]; }
  template <class BBox>
  bool kdtree_get_bbox(BBox&) const {
    return false;
  }
};

using DescriptorTree = nanoflann::KDTreeSingleIndexAdaptor<
    nanoflann::L2_Simple_Adaptor<float, DescriptorSource, float>, DescriptorSource, -1, uint32_t>;

// Leaf size: nanoflann's default of 10 is a good compromise for 3D; the
// descriptor tree's leaves are visited almost all anyway in high dimension.
constexpr std::size_t kLeafSize = 10;

}  // namespace

struct PointKdTree::Impl {
  PointSource source;
  std::unique_ptr<PointTree> tree;
};

PointKdTree::PointKdTree() : impl_(std::make_unique<Impl>()) {}

PointKdTree::PointKdTree(std::vector<Eigen::Vector3f> points) : impl_(std::make_unique<Impl>()) {
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) {
      throw std::invalid_argument("PointKdTree: point " + std::to_string(i) +
                                  " is not finite (expected finite coordinates)");
    }
  }
  impl_->source.points = std::move(points);
  impl_->tree = std::make_unique<PointTree>(3, impl_->source,
                                            nanoflann::KDTreeSingleIndexAdaptorParams(kLeafSize));
}

PointKdTree::~PointKdTree() = default;
PointKdTree::PointKdTree(PointKdTree&&) noexcept = default;
PointKdTree& PointKdTree::operator=(PointKdTree&&) noexcept = default;

const std::vector<Eigen::Vector3f>& PointKdTree::points() const { return impl_->source.points; }

bool PointKdTree::Nearest(const Eigen::Vector3f& query, float max_distance_m,
                          Neighbour* out) const {
  if (!impl_->tree || impl_->source.points.empty()) return false;
  uint32_t index = 0;
  float distance_sq = 0.0f;
  if (impl_->tree->knnSearch(query.data(), 1, &index, &distance_sq) == 0) return false;
  if (distance_sq > max_distance_m * max_distance_m) return false;
  *out = {index, distance_sq};
  return true;
}

void PointKdTree::Nearest(const Eigen::Vector3f& query, std::size_t k,
                          std::vector<Neighbour>* out) const {
  out->clear();
  if (!impl_->tree || impl_->source.points.empty() || k == 0) return;
  std::vector<uint32_t> indices(k);
  std::vector<float> distances(k);
  const std::size_t n = impl_->tree->knnSearch(query.data(), k, indices.data(), distances.data());
  for (std::size_t i = 0; i < n; ++i) out->push_back({indices[i], distances[i]});
}

void PointKdTree::Radius(const Eigen::Vector3f& query, float radius_m,
                         std::vector<Neighbour>* out) const {
  out->clear();
  if (!impl_->tree || impl_->source.points.empty()) return;
  std::vector<std::pair<uint32_t, float>> found;
  nanoflann::SearchParams params;
  params.sorted = false;
  impl_->tree->radiusSearch(query.data(), radius_m * radius_m, found, params);
  out->reserve(found.size());
  for (const auto& [index, distance_sq] : found) out->push_back({index, distance_sq});
}

struct DescriptorIndex::Impl {
  Eigen::MatrixXf descriptors;
  DescriptorSearch search = DescriptorSearch::kKdTree;
  DescriptorSource source;
  std::unique_ptr<DescriptorTree> tree;
  Eigen::VectorXf norms_sq;
};

DescriptorIndex::DescriptorIndex() : impl_(std::make_unique<Impl>()) {}

DescriptorIndex::DescriptorIndex(const Eigen::MatrixXf& descriptors, DescriptorSearch search)
    : impl_(std::make_unique<Impl>()) {
  for (Eigen::Index r = 0; r < descriptors.rows(); ++r) {
    if (!descriptors.row(r).allFinite()) {
      throw std::invalid_argument("DescriptorIndex: descriptor " + std::to_string(r) +
                                  " has a non-finite entry (expected finite values)");
    }
  }
  impl_->descriptors = descriptors;
  impl_->search = search;
  impl_->norms_sq = descriptors.rowwise().squaredNorm();
  if (search == DescriptorSearch::kKdTree && descriptors.rows() > 0) {
    DescriptorSource& s = impl_->source;
    s.rows = static_cast<std::size_t>(descriptors.rows());
    s.cols = static_cast<std::size_t>(descriptors.cols());
    s.data.resize(s.rows * s.cols);
    Eigen::Map<Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
        s.data.data(), descriptors.rows(), descriptors.cols()) = descriptors;
    impl_->tree = std::make_unique<DescriptorTree>(
        static_cast<int>(s.cols), s, nanoflann::KDTreeSingleIndexAdaptorParams(kLeafSize));
  }
}

DescriptorIndex::~DescriptorIndex() = default;
DescriptorIndex::DescriptorIndex(DescriptorIndex&&) noexcept = default;
DescriptorIndex& DescriptorIndex::operator=(DescriptorIndex&&) noexcept = default;

const Eigen::MatrixXf& DescriptorIndex::descriptors() const { return impl_->descriptors; }
std::size_t DescriptorIndex::size() const {
  return static_cast<std::size_t>(impl_->descriptors.rows());
}
DescriptorSearch DescriptorIndex::search() const { return impl_->search; }

std::vector<std::vector<Neighbour>> DescriptorIndex::Nearest(const Eigen::MatrixXf& queries,
                                                             std::size_t k) const {
  const Eigen::MatrixXf& d = impl_->descriptors;
  std::vector<std::vector<Neighbour>> result(static_cast<std::size_t>(queries.rows()));
  if (d.rows() == 0 || k == 0 || queries.rows() == 0) return result;
  if (queries.cols() != d.cols()) {
    throw std::invalid_argument("DescriptorIndex::Nearest: queries have " +
                                std::to_string(queries.cols()) + " columns, expected " +
                                std::to_string(d.cols()));
  }
  k = std::min<std::size_t>(k, static_cast<std::size_t>(d.rows()));
  if (impl_->search == DescriptorSearch::kKdTree) {
    std::vector<uint32_t> indices(k);
    std::vector<float> distances(k);
    Eigen::VectorXf q(d.cols());
    for (Eigen::Index r = 0; r < queries.rows(); ++r) {
      q = queries.row(r).transpose();
      const std::size_t n = impl_->tree->knnSearch(q.data(), k, indices.data(), distances.data());
      auto& out = result[static_cast<std::size_t>(r)];
      for (std::size_t i = 0; i < n; ++i) out.push_back({indices[i], distances[i]});
    }
    return result;
  }
  // |q - d|^2 = |q|^2 + |d|^2 - 2 q.d, a block of queries at a time so that
  // the product stays in cache.
  constexpr Eigen::Index kBlock = 128;
  std::vector<std::pair<float, uint32_t>> row;
  for (Eigen::Index r0 = 0; r0 < queries.rows(); r0 += kBlock) {
    const Eigen::Index n = std::min(kBlock, queries.rows() - r0);
    const Eigen::MatrixXf dots = queries.middleRows(r0, n) * d.transpose();
    for (Eigen::Index i = 0; i < n; ++i) {
      const float q_sq = queries.row(r0 + i).squaredNorm();
      row.resize(static_cast<std::size_t>(d.rows()));
      for (Eigen::Index j = 0; j < d.rows(); ++j) {
        row[static_cast<std::size_t>(j)] = {
            std::max(0.0f, q_sq + impl_->norms_sq[j] - 2.0f * dots(i, j)),
            static_cast<uint32_t>(j)};
      }
      std::partial_sort(row.begin(), row.begin() + static_cast<std::ptrdiff_t>(k), row.end());
      auto& out = result[static_cast<std::size_t>(r0 + i)];
      for (std::size_t m = 0; m < k; ++m) out.push_back({row[m].second, row[m].first});
    }
  }
  return result;
}

}  // namespace rover::mapping
