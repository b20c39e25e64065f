#ifndef ROVER_MAPPING_SUBMAP_SUBMAP_CODEC_H_
#define ROVER_MAPPING_SUBMAP_SUBMAP_CODEC_H_

// A submap's voxel space as bytes, in OctoMap's own file formats so that
// its tools (octovis, convert_octree) read them:
//  - binary (.bt, writeBinaryConst): 2 bits per node, occupied or free by
//    the tree's threshold; compact, what goes over the radio. Decoded, free
//    leaves carry the clamping minimum and occupied ones the maximum.
//  - full (.ot, AbstractOcTree::write): every node's log-odds (4 bytes).
// Neither stores the sensor model (hit, miss, clamping): a decoded tree has
// OctoMap's defaults, which are the thesis's.
//
// OctoMap's readers report malformed input on stderr and return false or
// null, and on truncated or corrupt data may read uninitialised bytes or
// recurse without bound. The decoders here check the header and walk the
// node structure over the bytes first (depth <= 16, node count, length),
// so that only well-formed streams reach OctoMap, and throw
// std::runtime_error saying what is wrong.

#include <memory>
#include <string>
#include <string_view>

#include <octomap/OcTree.h>

namespace rover::mapping {

/// The .bt stream of `tree` (not pruned or changed; prune first for fewer
/// bytes).
std::string EncodeOctreeBinary(const octomap::OcTree& tree);

/// Reads a .bt stream. Throws std::runtime_error for empty input, a stream
/// that is not an OctoMap binary OcTree, or one whose data is truncated or
/// inconsistent with its header.
std::unique_ptr<octomap::OcTree> DecodeOctreeBinary(std::string_view bytes);

/// The .ot stream of `tree` (full log-odds per node).
std::string EncodeOctreeFull(const octomap::OcTree& tree);

/// Reads a .ot stream; throws std::runtime_error as DecodeOctreeBinary.
std::unique_ptr<octomap::OcTree> DecodeOctreeFull(std::string_view bytes);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_SUBMAP_SUBMAP_CODEC_H_
