#ifndef ROVER_MAPPING_COMPOSE_MAP_EXPORT_H_
#define ROVER_MAPPING_COMPOSE_MAP_EXPORT_H_

// Files of the composed global map for operators and offline tools: the
// octree as OctoMap's .bt / .ot (Debian's octovis opens both) and the point
// cloud as PLY (MeshLab, CloudCompare, Open3D).
//
// Every writer writes `<path>.tmp`, flushes it to disk and renames it over
// `<path>`, so a crash or power loss mid-write never leaves a partial file
// under the final name (a previous file of that name stays intact until the
// rename). Two writers of one path at once are not supported. All functions
// throw std::runtime_error naming the path and what failed.

#include <filesystem>

#include <octomap/OcTree.h>

#include "mapping/submap/cloud_point.h"

namespace rover::mapping {

/// Writes `tree` as a binary .bt file (OcTree::writeBinaryConst): maximum
/// likelihood only, each known voxel free or occupied, no probabilities;
/// compact. Pruning the tree first makes the file smaller.
void WriteOctreeBt(const octomap::OcTree& tree, const std::filesystem::path& path);

/// Writes `tree` as a full .ot file (AbstractOcTree::write): every voxel's
/// log-odds, so the probabilities survive; read back with
/// octomap::AbstractOcTree::read.
void WriteOctreeOt(const octomap::OcTree& tree, const std::filesystem::path& path);

/// Writes a world-frame cloud (as from MapComposer::ComposedCloud) as a
/// binary little-endian PLY file: per vertex float x, y, z (m), uchar red,
/// green, blue (obstacles red, the rest grey, for viewers) and uchar
/// obstacle (0 or 1, for tools).
void WritePly(const PointCloud& cloud_world, const std::filesystem::path& path);

/// Reads a PLY file in exactly the layout WritePly writes (for tests and
/// tools): obstacle is taken from the obstacle property, colours are
/// ignored. Throws std::runtime_error naming the path on a malformed
/// header, or on data shorter or longer than the header declares (with
/// the vertex counts declared and present).
PointCloud ReadPly(const std::filesystem::path& path);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_COMPOSE_MAP_EXPORT_H_
