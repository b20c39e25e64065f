#include "mapping/loop/submap_pairing.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <tuple>

#include "core/geometry/so3.h"
#include "mapping/loop/option_checks.h"

namespace rover::mapping {
namespace {

using loop_internal::CheckPositive;
using loop_internal::CheckRange;

void CheckFinite(const char* caller, const SubmapId& id, const Eigen::Isometry3d& T,
                 const Matrix6d& covariance) {
  if (!T.matrix().allFinite()) {
    throw std::invalid_argument(std::string(caller) + ": T_world_origin of submap " +
                                id.ToString() + " has a non-finite entry (expected finite)");
  }
  if (!covariance.allFinite()) {
    throw std::invalid_argument(std::string(caller) + ": covariance of submap " + id.ToString() +
                                " has a non-finite entry (expected finite)");
  }
}

// The world-frame xy box of a submap-frame box.
Eigen::AlignedBox2d WorldBox(const Eigen::AlignedBox2d& box, const Eigen::Isometry3d& T) {
  Eigen::AlignedBox2d out;
  if (box.isEmpty()) return out;
  for (int c = 0; c < 4; ++c) {
    const Eigen::Vector2d corner = box.corner(static_cast<Eigen::AlignedBox2d::CornerType>(c));
    out.extend((T * Eigen::Vector3d(corner.x(), corner.y(), 0.0)).head<2>());
  }
  return out;
}

// Covariance of T_b_a from that of T_a_b (both over [dp; dtheta (right)]),
// to first order: inverting T = (t + dp, R Exp(dtheta)) gives
// dp' = -R^T dp + [t']x dtheta and dtheta' = -R dtheta, t' = -R^T t.
Matrix6d InverseCovariance(const Eigen::Isometry3d& T_a_b, const Matrix6d& covariance) {
  const Eigen::Matrix3d R = T_a_b.linear();
  const Eigen::Vector3d t_b_a = -R.transpose() * T_a_b.translation();
  Matrix6d J = Matrix6d::Zero();
  J.block<3, 3>(0, 0) = -R.transpose();
  J.block<3, 3>(0, 3) = skew(t_b_a);
  J.block<3, 3>(3, 3) = -R;
  return J * covariance * J.transpose();
}

}  // namespace

double ObstacleBoxOverlapM2(const Eigen::AlignedBox2d& box_a, const Eigen::Isometry3d& T_world_a,
                            const Eigen::AlignedBox2d& box_b, const Eigen::Isometry3d& T_world_b,
                            const Eigen::Vector2d& enlarge_m) {
  const Eigen::AlignedBox2d world_a = WorldBox(box_a, T_world_a);
  const Eigen::AlignedBox2d world_b = WorldBox(box_b, T_world_b);
  if (world_a.isEmpty() || world_b.isEmpty()) return 0.0;
  double area = 1.0;
  for (int t = 0; t < 2; ++t) {
    const double overlap =
        std::min(world_a.max()(t), world_b.max()(t)) - std::max(world_a.min()(t), world_b.min()(t));
    area *= std::max(0.0, overlap + enlarge_m(t));
  }
  return area;
}

bool SubmapPairing::WorseScore::operator()(const SubmapPair& x, const SubmapPair& y) const {
  if (x.score != y.score) return x.score < y.score;
  // Equal scores: the smaller ids first, for a deterministic order.
  return std::tie(x.a, x.b) > std::tie(y.a, y.b);
}

void SubmapPairingOptions::Validate() const {
  constexpr const char* kC = "SubmapPairingOptions";
  CheckRange(kC, "min_overlap_m2", min_overlap_m2, 0.0, 1e9);
  CheckRange(kC, "overlap_sigma_factor", overlap_sigma_factor, 0.0, 100.0);
  CheckRange(kC, "alpha", alpha, 0.0, 1e6);
  CheckRange(kC, "pixel_error_px", pixel_error_px, 0.0, 100.0);
  CheckPositive(kC, "focal_px", focal_px);
  CheckPositive(kC, "baseline_m", baseline_m);
  CheckRange(kC, "view_distance_m", view_distance_m, 0.0, 1e3);
}

SubmapPairingOptions SubmapPairingOptions::Load(const ConfigNode& node) {
  return Load(node, SubmapPairingOptions{});
}

SubmapPairingOptions SubmapPairingOptions::Load(const ConfigNode& node,
                                                const SubmapPairingOptions& defaults) {
  SubmapPairingOptions o = defaults;
  o.min_overlap_m2 = node.Get<double>("min_overlap_m2", o.min_overlap_m2);
  o.overlap_sigma_factor = node.Get<double>("overlap_sigma_factor", o.overlap_sigma_factor);
  o.alpha = node.Get<double>("alpha", o.alpha);
  o.pixel_error_px = node.Get<double>("pixel_error_px", o.pixel_error_px);
  o.focal_px = node.Get<double>("focal_px", o.focal_px);
  o.baseline_m = node.Get<double>("baseline_m", o.baseline_m);
  o.view_distance_m = node.Get<double>("view_distance_m", o.view_distance_m);
  o.skip_successive = node.Get<bool>("skip_successive", o.skip_successive);
  o.Validate();
  return o;
}

double SubmapPairingOptions::MatcherPrecisionM() const {
  return pixel_error_px * view_distance_m * view_distance_m / (focal_px * baseline_m) *
         std::sqrt(2.0);
}

SubmapPairing::SubmapPairing(const SubmapPairingOptions& options) : options_(options) {
  options_.Validate();
}

void SubmapPairing::AddSubmap(const SubmapId& id, const SubmapMatchData& data,
                              const Eigen::Isometry3d& T_world_origin, const Matrix6d& covariance) {
  AddSubmap(id, data.suitable(), data.obstacle_box_xy(), T_world_origin, covariance);
}

void SubmapPairing::AddSubmap(const SubmapId& id, bool suitable,
                              const Eigen::AlignedBox2d& obstacle_box_xy,
                              const Eigen::Isometry3d& T_world_origin, const Matrix6d& covariance) {
  CheckFinite("SubmapPairing::AddSubmap", id, T_world_origin, covariance);
  if (submaps_.count(id)) {
    throw std::invalid_argument("SubmapPairing::AddSubmap: submap " + id.ToString() +
                                " was added before");
  }
  submaps_[id] = {suitable, obstacle_box_xy, T_world_origin, covariance};
  dirty_ = true;
}

const SubmapPairing::Entry& SubmapPairing::Find(const SubmapId& id, const char* caller) const {
  const auto it = submaps_.find(id);
  if (it == submaps_.end()) {
    throw std::invalid_argument(std::string(caller) + ": unknown submap " + id.ToString());
  }
  return it->second;
}

void SubmapPairing::UpdateOrigin(const SubmapId& id, const Eigen::Isometry3d& T_world_origin,
                                 const Matrix6d& covariance) {
  Find(id, "SubmapPairing::UpdateOrigin");
  CheckFinite("SubmapPairing::UpdateOrigin", id, T_world_origin, covariance);
  Entry& e = submaps_[id];
  e.T_world_origin = T_world_origin;
  e.covariance = covariance;
  // A relative covariance computed for the old estimates no longer holds.
  for (auto it = relative_.begin(); it != relative_.end();) {
    it = (it->first.first == id || it->first.second == id) ? relative_.erase(it) : std::next(it);
  }
  dirty_ = true;
}

SubmapPairing::Key SubmapPairing::Ordered(const SubmapId& a, const SubmapId& b) {
  return a < b ? Key{a, b} : Key{b, a};
}

void SubmapPairing::SetRelativeCovariance(const SubmapId& a, const SubmapId& b,
                                          const Matrix6d& covariance) {
  Find(a, "SubmapPairing::SetRelativeCovariance");
  Find(b, "SubmapPairing::SetRelativeCovariance");
  if (!covariance.allFinite()) {
    throw std::invalid_argument("SubmapPairing::SetRelativeCovariance: covariance of " +
                                a.ToString() + " - " + b.ToString() +
                                " has a non-finite entry (expected finite)");
  }
  relative_[Ordered(a, b)] = {a, covariance};
  dirty_ = true;
}

void SubmapPairing::MarkDone(const SubmapId& a, const SubmapId& b) {
  // Next() skips done pairs: no rebuild needed.
  done_.insert(Ordered(a, b));
}

bool SubmapPairing::IsDone(const SubmapId& a, const SubmapId& b) const {
  return done_.count(Ordered(a, b)) > 0;
}

int SubmapPairing::suitable_count() const {
  return static_cast<int>(std::count_if(submaps_.begin(), submaps_.end(),
                                        [](const auto& kv) { return kv.second.suitable; }));
}

SubmapPair SubmapPairing::Evaluate(const SubmapId& a, const SubmapId& b) const {
  const Entry& ea = Find(a, "SubmapPairing::Evaluate");
  const Entry& eb = Find(b, "SubmapPairing::Evaluate");
  SubmapPair pair;
  pair.a = a;
  pair.b = b;
  const Eigen::Matrix3d R_world_a = ea.T_world_origin.linear();
  pair.prior.T_a_b = ea.T_world_origin.inverse() * eb.T_world_origin;
  pair.prior.bounded = true;

  const auto given = relative_.find(Ordered(a, b));
  if (given != relative_.end()) {
    const Matrix6d cov = given->second.frame == a ? given->second.covariance
                                                  : InverseCovariance(pair.prior.T_a_b.inverse(),
                                                                      given->second.covariance);
    pair.prior.covariance = cov;
    const Eigen::Matrix3d world = R_world_a * cov.topLeftCorner<3, 3>() * R_world_a.transpose();
    pair.relative_sigma_m = world.diagonal().cwiseMax(0.0).cwiseSqrt();
  } else {
    // Per-axis approximation from the marginals (see the header).
    const bool same_robot = a.robot == b.robot;
    Eigen::Matrix<double, 6, 1> var;
    for (int i = 0; i < 6; ++i) {
      const double va = ea.covariance(i, i);
      const double vb = eb.covariance(i, i);
      var(i) = same_robot ? std::abs(va - vb) : va + vb;
    }
    pair.relative_sigma_m = var.head<3>().cwiseSqrt();
    Matrix6d cov = Matrix6d::Zero();
    cov.topLeftCorner<3, 3>() = R_world_a.transpose() * var.head<3>().asDiagonal() * R_world_a;
    cov.bottomRightCorner<3, 3>() = var.tail<3>().asDiagonal();
    pair.prior.covariance = cov;
  }

  // Eq. 6.1 / 6.2.
  pair.overlap_m2 =
      ObstacleBoxOverlapM2(ea.box_xy, ea.T_world_origin, eb.box_xy, eb.T_world_origin,
                           options_.overlap_sigma_factor * pair.relative_sigma_m.head<2>());
  // Eq. 6.4.
  pair.score = options_.alpha * pair.overlap_m2 + pair.relative_sigma_m.sum();
  return pair;
}

const char* PairVerdictName(PairVerdict verdict) {
  switch (verdict) {
    case PairVerdict::kCandidate:
      return "candidate";
    case PairVerdict::kSameSubmap:
      return "same submap";
    case PairVerdict::kUnsuitable:
      return "unsuitable submap";
    case PairVerdict::kSuccessive:
      return "successive submaps";
    case PairVerdict::kDone:
      return "matched before";
    case PairVerdict::kSmallOverlap:
      return "obstacle boxes overlap too little";
    case PairVerdict::kBelowMatcherPrecision:
      return "relative sigma below the matcher's precision";
  }
  return "unknown";
}

PairVerdict SubmapPairing::Check(const SubmapId& a, const SubmapId& b, SubmapPair* pair) const {
  const Entry& ea = Find(a, "SubmapPairing::Check");
  const Entry& eb = Find(b, "SubmapPairing::Check");
  if (a == b) return PairVerdict::kSameSubmap;
  if (!ea.suitable || !eb.suitable) return PairVerdict::kUnsuitable;
  if (options_.skip_successive && a.robot == b.robot && std::abs(a.index - b.index) == 1) {
    return PairVerdict::kSuccessive;
  }
  if (IsDone(a, b)) return PairVerdict::kDone;
  const SubmapPair evaluated = Evaluate(a, b);
  if (pair != nullptr) *pair = evaluated;
  if (!(evaluated.overlap_m2 > options_.min_overlap_m2)) return PairVerdict::kSmallOverlap;
  // Eq. 6.3: a relative uncertainty below the matcher's precision leaves
  // nothing to gain.
  if (evaluated.relative_sigma_m.mean() < options_.MatcherPrecisionM()) {
    return PairVerdict::kBelowMatcherPrecision;
  }
  return PairVerdict::kCandidate;
}

std::vector<SubmapPair> SubmapPairing::Candidates() const {
  std::vector<SubmapPair> out;
  for (auto ia = submaps_.begin(); ia != submaps_.end(); ++ia) {
    for (auto ib = std::next(ia); ib != submaps_.end(); ++ib) {
      SubmapPair pair;
      if (Check(ia->first, ib->first, &pair) == PairVerdict::kCandidate) out.push_back(pair);
    }
  }
  std::sort(out.begin(), out.end(),
            [](const SubmapPair& x, const SubmapPair& y) { return WorseScore()(y, x); });
  return out;
}

std::optional<SubmapPair> SubmapPairing::Next() {
  if (dirty_) {
    std::vector<SubmapPair> all = Candidates();
    queue_ = decltype(queue_)(WorseScore(), std::move(all));
    dirty_ = false;
  }
  while (!queue_.empty()) {
    SubmapPair top = queue_.top();
    queue_.pop();
    if (IsDone(top.a, top.b)) continue;  // marked done since the rebuild
    done_.insert(Ordered(top.a, top.b));
    return top;
  }
  return std::nullopt;
}

}  // namespace rover::mapping
