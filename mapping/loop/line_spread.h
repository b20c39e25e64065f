#ifndef ROVER_MAPPING_LOOP_LINE_SPREAD_H_
#define ROVER_MAPPING_LOOP_LINE_SPREAD_H_

// How far a set of keypoints spreads beyond a line (thesis section 6.1.1,
// submap suitability, and 6.1.2, per hypothesis): keypoints along one
// straight structure (a wall, a row of rocks) or around one small rock leave
// a match ambiguous along the line or in yaw. RANSAC fits a line through two
// keypoints; distances are measured in the xy-plane, as the thesis counts
// them, and the line with the most keypoints within `off_line_distance_m` is
// kept, so that the count below is that of the best-fitting line (if any
// line leaves few keypoints off it, the set is ambiguous).

#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace rover::mapping {

/// Keypoints farther than `off_line_distance_m` (xy) from the best-fitting
/// line. A sample whose two points coincide in xy (a vertical line) measures
/// distances to that point. Up to `max_samples` random pairs (seeded by
/// `seed`); when all pairs are fewer, all are tried (exact and
/// deterministic).
int CountOffLine(const std::vector<Eigen::Vector3f>& points, double off_line_distance_m,
                 int max_samples, uint64_t seed);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_LOOP_LINE_SPREAD_H_
