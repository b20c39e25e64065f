#ifndef ROVER_MAPPING_TAGS_TAG_AMBIGUITY_RESOLVER_H_
#define ROVER_MAPPING_TAGS_TAG_AMBIGUITY_RESOLVER_H_

// Decides between the two solutions of ambiguous tag detections by the tag's
// other sightings. A fixed tag stays where it is: placed in the filter's
// local frame (the camera's estimate then, composed with each solution), the
// true solutions of successive sightings agree, while the wrong ones, the
// true pose mirrored about the line of sight, swing as the line of sight
// turns with the rover's motion. A solution is chosen once enough sightings
// of the same tag in the same local frame agree on it and no rival comes
// close; detections that fit neither are refused. Within one local frame
// only: the filter's drift there is millimetres and a fraction of a degree.
// Not thread-safe.

#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "mapping/tags/tag_observer.h"

namespace rover::mapping {

struct TagAmbiguityOptions {
  /// Two placements of the tag agree within this rotation [rad] and
  /// distance between the tag centres [m], or within agree_sigmas of their
  /// combined standard deviations where those are larger.
  double agree_rad = 5.0 * 3.14159265358979323846 / 180.0;
  double agree_m = 0.10;
  double agree_sigmas = 2.5;
  /// ... but never wider in rotation than this [rad]: the two solutions of
  /// the ambiguity lie 20 degrees or more apart, so a wider tolerance (the
  /// table's rotation sigma at 4-5 m is several degrees) lets the wrong
  /// solutions of a few sightings agree with each other or the right one.
  double max_agree_rad = 10.0 * 3.14159265358979323846 / 180.0;
  /// Sightings that must agree on a placement before it is taken.
  int min_support = 4;
  /// ... seen along lines of sight at least this far apart [rad]. Driving
  /// straight at a tag, its wrong solution (mirrored about the line of
  /// sight) stays put as the right one does, and agreement says nothing:
  /// in the landmark missions a tag approached head-on was decided wrong
  /// twice.
  double min_view_change_rad = 10.0 * 3.14159265358979323846 / 180.0;
  /// ... and the best rival placement may have at most this fraction of its
  /// support.
  double max_rival_fraction = 0.5;
  /// Undecided sightings older than this are refused [s]; so are those of a
  /// local frame that has ended.
  double max_wait_s = 30.0;
  /// Sightings kept per tag and frame (the oldest go first).
  int max_sightings = 48;

  /// Throws std::invalid_argument "TagAmbiguityOptions.<key>: ...".
  void Validate() const;
};

/// One sighting of one tag: one placement (an accepted detection, which
/// votes) or two (an ambiguous one, which waits for a decision).
struct TagPlacements {
  uint64_t key = 0;  ///< the caller's handle, returned in the decision
  int64_t stamp_ns = 0;
  int tag_id = 0;
  uint32_t frame_id = 0;
  /// T_local_tag of each solution (best first).
  std::vector<Eigen::Isometry3d> T_local_tag{};
  /// Each solution's largest rotation [rad] and position [m] standard
  /// deviation (empty: agree_rad and agree_m alone decide).
  std::vector<double> rotation_sigma_rad{};
  std::vector<double> position_sigma_m{};
  /// Where the camera was [m, local frame].
  Eigen::Vector3d p_local_cam = Eigen::Vector3d::Zero();
};

struct TagDecision {
  uint64_t key = 0;
  int solution = -1;  ///< 0 best, 1 alternative; -1 neither
  /// With solution -1: true if the sightings could not decide (too few, or a
  /// rival placement too close: the caller may keep the detection with its
  /// rotation left open), false if they decided against both solutions.
  bool undecided = false;
  std::string refusal;  ///< why no solution was chosen
  int support = 0;      ///< sightings that agreed with the chosen placement
};

/// The placements an observation of a tag seen from T_local_cam gives: its
/// best solution if accepted (a vote), both solutions if ambiguous (to be
/// decided), none otherwise; with their sigmas.
TagPlacements PlacementsOf(const TagObservation& observation, const Eigen::Isometry3d& T_local_cam,
                           uint64_t key, int64_t stamp_ns, uint32_t frame_id);

class TagAmbiguityResolver {
 public:
  /// Throws std::invalid_argument for invalid options.
  explicit TagAmbiguityResolver(const TagAmbiguityOptions& options = {});

  /// Adds a sighting (one or two placements; anything else throws
  /// std::invalid_argument). Returns the decisions it makes possible for the
  /// waiting ambiguous sightings, this one included; sightings of earlier
  /// frames than `frame_id` that still wait are refused.
  std::vector<TagDecision> Add(const TagPlacements& sighting);

  /// Refuses every sighting still waiting (at shutdown), and those older
  /// than max_wait_s before `now_ns`.
  std::vector<TagDecision> Expire(int64_t now_ns, bool all = false);

  std::size_t waiting() const;

 private:
  struct Group {
    std::vector<TagPlacements> sightings;
    std::vector<bool> waiting;
  };
  /// Decides the waiting sightings of `group` if its placements allow.
  void Decide(Group* group, std::vector<TagDecision>* out) const;
  /// Placement i of sighting a against placement j of sighting b.
  bool Agree(const TagPlacements& a, std::size_t i, const TagPlacements& b, std::size_t j) const;
  /// The widest angle [rad] between the lines of sight of the sightings
  /// that agree with placement i of `chosen`.
  double ViewChange(const std::vector<TagPlacements>& all, const TagPlacements& chosen,
                    std::size_t i) const;

  TagAmbiguityOptions options_;
  std::map<std::pair<uint32_t, int>, Group> groups_;  ///< by (frame, tag id)
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_TAGS_TAG_AMBIGUITY_RESOLVER_H_
