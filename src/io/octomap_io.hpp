#pragma once
// OctoMap files (.bt: binary occupancy, .ot: full tree), through Debian's
// liboctomap: a map is the centres of its occupied leaves.
#include <string>

#include "core/types.hpp"

namespace tomomap {

/// The centres of the occupied voxels of an OcTree file (`binary`: .bt, else
/// .ot), at the tree's finest resolution (a pruned leaf stands for all the
/// voxels inside it). Throws InputError for a file that is not an OcTree, or
/// one that would expand past kMaxOctomapPoints.
Points loadOctomap(const std::string& path, bool binary);

constexpr size_t kMaxOctomapPoints = 100'000'000;  ///< 1.2 GB as points: beyond, the tree is not a robot's map

}  // namespace tomomap
