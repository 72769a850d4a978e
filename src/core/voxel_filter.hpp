#pragma once
#include "types.hpp"

namespace tomomap {

/// Replaces the points of every occupied cube of edge `leaf` [m] by their centroid.
/// Hash-based so that it works for any map extent (PCL's VoxelGrid refuses extents
/// whose cell count overflows 32 bits, e.g. 1 km at 0.05 m). Output order is
/// deterministic (sorted by cell).
Points voxelFilter(const Points& in, double leaf);

}  // namespace tomomap
