#pragma once
#include "types.hpp"

namespace tomomap {

/// Replaces the points of every occupied cube of edge `leaf` [m] by their centroid.
/// Hash-based so that it works for any map extent (PCL's VoxelGrid refuses extents
/// whose cell count overflows 32 bits, e.g. 1 km at 0.05 m). Output order is
/// deterministic (sorted by cell). The cubes start at the points' lowest
/// corner, or at `*corner` where it is given and no point lies below it (a map
/// described again on its earlier version's cubes); `*corner` returns the one used.
Points voxelFilter(const Points& in, double leaf, Eigen::Vector3f* corner = nullptr);

}  // namespace tomomap
