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

void TagAmbiguityOptions::Validate() const {
  Require(agree_rad > 0.0 && agree_rad < 1.0, "agree_rad", "in (0, 1) rad");
  Require(agree_m > 0.0 && std::isfinite(agree_m), "agree_m", "> 0 m");
  Require(min_support >= 2, "min_support", ">= 2 sightings");
  Require(max_rival_fraction >= 0.0 && max_rival_fraction < 1.0, "max_rival_fraction", "in [0, 1)");
  Require(max_wait_s > 0.0 && std::isfinite(max_wait_s), "max_wait_s", "> 0 s");
  Require(max_sightings >= min_support, "max_sightings", ">= min_support");
}

TagAmbiguityResolver::TagAmbiguityResolver(const TagAmbiguityOptions& options) : options_(options) {
  options_.Validate();
}

bool TagAmbiguityResolver::Agree(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) const {
  const double angle = Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle();
  return angle <= options_.agree_rad &&
         (a.translation() - b.translation()).norm() <= options_.agree_m;
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
  // Support of a placement: the sightings with a solution that agrees with it.
  const auto support = [&](const Eigen::Isometry3d& T) {
    int n = 0;
    for (const TagPlacements& s : g->sightings) {
      bool agrees = false;
      for (const Eigen::Isometry3d& other : s.T_local_tag) agrees = agrees || Agree(T, other);
      n += agrees;
    }
    return n;
  };
  const Eigen::Isometry3d* best = nullptr;
  int best_support = 0;
  for (const TagPlacements& s : g->sightings) {
    for (const Eigen::Isometry3d& T : s.T_local_tag) {
      const int n = support(T);
      if (n > best_support) {
        best_support = n;
        best = &T;
      }
    }
  }
  if (best == nullptr || best_support < options_.min_support) return;
  int rival_support = 0;
  for (const TagPlacements& s : g->sightings) {
    for (const Eigen::Isometry3d& T : s.T_local_tag) {
      if (!Agree(T, *best)) rival_support = std::max(rival_support, support(T));
    }
  }
  if (rival_support > options_.max_rival_fraction * best_support) return;
  for (std::size_t k = 0; k < g->sightings.size(); ++k) {
    if (!g->waiting[k]) continue;
    g->waiting[k] = false;
    const TagPlacements& s = g->sightings[k];
    TagDecision d;
    d.key = s.key;
    d.support = best_support;
    for (int i = 0; i < static_cast<int>(s.T_local_tag.size()) && d.solution < 0; ++i) {
      if (Agree(s.T_local_tag[static_cast<std::size_t>(i)], *best)) d.solution = i;
    }
    if (d.solution < 0) {
      d.refusal = "ambiguous, and neither solution agrees with the tag's other sightings";
    }
    out->push_back(d);
  }
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
