#pragma once
// How well the occupancy pins a pose down: the best of the poses around it.
#include "dense_search.hpp"

namespace tomomap {

/// The best-scoring pose among `T` shifted by every whole grid cell more than
/// `inner_cells` and at most `outer_cells` away, at T's yaw and within a slice
/// of its height offset (a feature answer's height is a slice or two off,
/// height_offsets.hpp), each judged as the dense search judges its poses (landPoses). A pose whose
/// neighbourhood holds one that lands as much lies on a ridge of the
/// occupancy (a street's facades, two parallel walls) that the coarse raster
/// of a dense search cannot resolve. Nothing landed (all counts 0) where
/// either stack is partial.
DensePose bestAround(const SliceStack& target, const SliceStack& source, const Rigid2D& T, int offset, int inner_cells,
                     int outer_cells, const DenseSearchParams& params = {});

}  // namespace tomomap
