#pragma once
// OctoMap trees, through Debian's liboctomap: files (.bt: binary occupancy,
// .ot: full tree) and the payload of ROS's octomap_msgs/Octomap; a map is the
// centres of its occupied leaves.
#include <cstdint>
#include <string>
#include <vector>

#include "core/types.hpp"

namespace tomomap {

/// The centres of the occupied voxels of an OcTree file (`binary`: .bt, else
/// .ot), at the tree's finest resolution (a pruned leaf stands for all the
/// voxels inside it). Throws InputError for a file that is not an OcTree, or
/// one that would expand past kMaxOctomapPoints.
Points loadOctomap(const std::string& path, bool binary);

/// The same for an octomap_msgs/Octomap message's tree: `data` as octomap
/// serialises it (octomap_msgs's binaryMapToMsg: OcTree::writeBinaryData;
/// fullMapToMsg: writeData of the tree named `id`), read back by octomap's own
/// readBinaryData / readData at `resolution` [m]. Throws InputError for data
/// that is not such a tree, or another kind of tree than an OcTree.
Points octomapFromMessage(bool binary, const std::string& id, double resolution, const std::vector<uint8_t>& data);

constexpr size_t kMaxOctomapPoints = 100'000'000;  ///< 1.2 GB as points: beyond, the tree is not a robot's map

}  // namespace tomomap
