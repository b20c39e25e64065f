#include "mapping/tags/tag_ambiguity_resolver.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rover::mapping {
namespace {

void Require(bool ok, const std::string& key, const std::string& expected) {
  if (!ok) throw std::invalid_argument("TagAmbiguityOptions." + key + ": expected " + expected);
}

TagDecision Undecided(const TagPlacements& s, std::string why) {
  TagDecision d;
  d.key = s.key;
  d.undecided = true;
  d.refusal = std::move(why);
  return d;
}

}  // namespace

TagPlacements PlacementsOf(const TagObservation& o, const Eigen::Isometry3d& T_local_cam,
                           uint64_t key, int64_t stamp_ns, uint32_t frame_id) {
  TagPlacements p{.key = key, .stamp_ns = stamp_ns, .tag_id = o.detection.id, .frame_id = frame_id};
  p.p_local_cam = T_local_cam.translation();
  const auto add = [&](const Eigen::Isometry3d& T_camera_tag, const TagUncertainty& u) {
    p.T_local_tag.push_back(T_local_cam * T_camera_tag);
    p.rotation_sigma_rad.push_back(u.sigma.tail<3>().maxCoeff());
    p.position_sigma_m.push_back(u.sigma.head<3>().maxCoeff());
  };
  if (!o.pose) return p;
  if (o.accepted) {
    add(o.pose->best.T_camera_tag, o.uncertainty);
  } else if (o.uncertainty.ambiguous) {
    add(o.pose->best.T_camera_tag, o.solutions[0]);
    add(o.pose->alternative.T_camera_tag, o.solutions[1]);
  }
  return p;
}

void TagAmbiguityOptions::Validate() const {
  Require(agree_rad > 0.0 && agree_rad < 1.0, "agree_rad", "in (0, 1) rad");
  Require(agree_m > 0.0 && std::isfinite(agree_m), "agree_m", "> 0 m");
  Require(max_agree_rad >= agree_rad && max_agree_rad < 1.0, "max_agree_rad",
          "in [agree_rad, 1) rad");
  Require(agree_sigmas >= 0.0 && std::isfinite(agree_sigmas), "agree_sigmas", ">= 0");
  Require(min_support >= 2, "min_support", ">= 2 sightings");
  Require(min_view_change_rad >= 0.0 && min_view_change_rad < 3.2, "min_view_change_rad",
          "in [0, pi] rad");
  Require(max_rival_fraction >= 0.0 && max_rival_fraction < 1.0, "max_rival_fraction", "in [0, 1)");
  Require(max_wait_s > 0.0 && std::isfinite(max_wait_s), "max_wait_s", "> 0 s");
  Require(max_sightings >= min_support, "max_sightings", ">= min_support");
}

TagAmbiguityResolver::TagAmbiguityResolver(const TagAmbiguityOptions& options) : options_(options) {
  options_.Validate();
}

bool TagAmbiguityResolver::Agree(const TagPlacements& a, std::size_t i, const TagPlacements& b,
                                 std::size_t j) const {
  const auto sigma = [](const std::vector<double>& v, std::size_t k) {
    return k < v.size() ? v[k] : 0.0;
  };
  const double max_rad =
      std::min(options_.max_agree_rad,
               std::max(options_.agree_rad,
                        options_.agree_sigmas * std::hypot(sigma(a.rotation_sigma_rad, i),
                                                           sigma(b.rotation_sigma_rad, j))));
  const double max_m =
      std::max(options_.agree_m, options_.agree_sigmas * std::hypot(sigma(a.position_sigma_m, i),
                                                                    sigma(b.position_sigma_m, j)));
  const Eigen::Isometry3d& A = a.T_local_tag[i];
  const Eigen::Isometry3d& B = b.T_local_tag[j];
  return Eigen::AngleAxisd(A.linear().transpose() * B.linear()).angle() <= max_rad &&
         (A.translation() - B.translation()).norm() <= max_m;
}

std::size_t TagAmbiguityResolver::waiting() const {
  std::size_t n = 0;
  for (const auto& [key, g] : groups_) {
    for (const bool w : g.waiting) n += w;
  }
  return n;
}

std::vector<TagDecision> TagAmbiguityResolver::Add(const TagPlacements& sighting) {
  if (sighting.T_local_tag.empty() || sighting.T_local_tag.size() > 2) {
    throw std::invalid_argument("TagAmbiguityResolver::Add: expected 1 or 2 placements, found " +
                                std::to_string(sighting.T_local_tag.size()));
  }
  const std::size_t n = sighting.T_local_tag.size();
  if ((!sighting.rotation_sigma_rad.empty() && sighting.rotation_sigma_rad.size() != n) ||
      (!sighting.position_sigma_m.empty() && sighting.position_sigma_m.size() != n)) {
    throw std::invalid_argument(
        "TagAmbiguityResolver::Add: expected one sigma per placement or none");
  }
  std::vector<TagDecision> out;
  // A new frame: the waiting sightings of earlier ones can no longer be
  // compared with anything new.
  for (auto it = groups_.begin(); it != groups_.end();) {
    if (it->first.first >= sighting.frame_id) {
      ++it;
      continue;
    }
    for (std::size_t k = 0; k < it->second.sightings.size(); ++k) {
      if (it->second.waiting[k]) {
        out.push_back(Undecided(it->second.sightings[k],
                                "ambiguous, and its local frame ended before enough sightings "
                                "agreed"));
      }
    }
    it = groups_.erase(it);
  }
  Group& g = groups_[{sighting.frame_id, sighting.tag_id}];
  if (static_cast<int>(g.sightings.size()) >= options_.max_sightings) {
    if (g.waiting.front()) {
      out.push_back(Undecided(g.sightings.front(), "ambiguous, and still undecided"));
    }
    g.sightings.erase(g.sightings.begin());
    g.waiting.erase(g.waiting.begin());
  }
  g.sightings.push_back(sighting);
  g.waiting.push_back(sighting.T_local_tag.size() == 2);
  Decide(&g, &out);
  return out;
}

void TagAmbiguityResolver::Decide(Group* g, std::vector<TagDecision>* out) const {
  bool any_waiting = false;
  for (const bool w : g->waiting) any_waiting = any_waiting || w;
  if (!any_waiting) return;
  const std::vector<TagPlacements>& all = g->sightings;
  // Support of placement (s, i): the sightings with a solution that agrees.
  const auto support = [&](std::size_t s, std::size_t i) {
    int n = 0;
    for (const TagPlacements& other : all) {
      bool agrees = false;
      for (std::size_t j = 0; j < other.T_local_tag.size() && !agrees; ++j) {
        agrees = Agree(all[s], i, other, j);
      }
      n += agrees;
    }
    return n;
  };
  std::size_t best_s = 0, best_i = 0;
  int best_support = 0;
  for (std::size_t s = 0; s < all.size(); ++s) {
    for (std::size_t i = 0; i < all[s].T_local_tag.size(); ++i) {
      const int n = support(s, i);
      if (n > best_support) {
        best_support = n;
        best_s = s;
        best_i = i;
      }
    }
  }
  if (best_support < options_.min_support) return;
  if (ViewChange(all, all[best_s], best_i) < options_.min_view_change_rad) return;
  int rival_support = 0;
  for (std::size_t s = 0; s < all.size(); ++s) {
    for (std::size_t i = 0; i < all[s].T_local_tag.size(); ++i) {
      if (!Agree(all[s], i, all[best_s], best_i))
        rival_support = std::max(rival_support, support(s, i));
    }
  }
  if (rival_support > options_.max_rival_fraction * best_support) return;
  for (std::size_t k = 0; k < all.size(); ++k) {
    if (!g->waiting[k]) continue;
    g->waiting[k] = false;
    TagDecision d;
    d.key = all[k].key;
    d.support = best_support;
    for (std::size_t i = 0; i < all[k].T_local_tag.size() && d.solution < 0; ++i) {
      if (Agree(all[k], i, all[best_s], best_i)) d.solution = static_cast<int>(i);
    }
    if (d.solution < 0) {
      d.refusal = "ambiguous, and neither solution agrees with the tag's other sightings";
    }
    out->push_back(d);
  }
}

double TagAmbiguityResolver::ViewChange(const std::vector<TagPlacements>& all,
                                        const TagPlacements& chosen, std::size_t i) const {
  // The widest angle between two supporting sightings' lines of sight to
  // the chosen placement.
  const Eigen::Vector3d p_local_tag = chosen.T_local_tag[i].translation();
  std::vector<Eigen::Vector3d> rays;
  for (const TagPlacements& other : all) {
    for (std::size_t j = 0; j < other.T_local_tag.size(); ++j) {
      if (!Agree(chosen, i, other, j)) continue;
      const Eigen::Vector3d ray = p_local_tag - other.p_local_cam;
      if (ray.norm() > 0.0) rays.push_back(ray.normalized());
      break;
    }
  }
  double widest = 0.0;
  for (std::size_t a = 0; a < rays.size(); ++a) {
    for (std::size_t b = a + 1; b < rays.size(); ++b) {
      widest = std::max(widest, std::acos(std::clamp(rays[a].dot(rays[b]), -1.0, 1.0)));
    }
  }
  return widest;
}

std::vector<TagDecision> TagAmbiguityResolver::Expire(int64_t now_ns, bool all) {
  std::vector<TagDecision> out;
  const auto max_wait_ns = static_cast<int64_t>(options_.max_wait_s * 1e9);
  for (auto& [key, g] : groups_) {
    for (std::size_t k = 0; k < g.sightings.size(); ++k) {
      if (g.waiting[k] && (all || now_ns - g.sightings[k].stamp_ns > max_wait_ns)) {
        g.waiting[k] = false;
        out.push_back(Undecided(
            g.sightings[k],
            all ? "ambiguous, and undecided when the sightings ended"
                : "ambiguous, and undecided after " + std::to_string(options_.max_wait_s) + " s"));
      }
    }
  }
  return out;
}

}  // namespace rover::mapping
