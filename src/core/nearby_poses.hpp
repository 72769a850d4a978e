#pragma once
// The pose uphill of a pose on the maps' occupancy: how each candidate is
// refined before it is judged (candidates.hpp).
#include "dense_refine.hpp"
#include "pose_lander.hpp"

namespace tomomap {

/// The pose uphill of (T, offset): it climbs, one step at a time while a step
/// lands more telling cells (PoseLander::scores): a grid cell in x or y, the yaw that
/// moves the source raster's corner by a cell (turning about its centre), a
/// slice in height. Where it stops, it is refined on the occupancy
/// (refineOnOccupancy: nearest cells, not the count) and climbs again, while
/// that lands more. A dense search's pose is refined from its coarse cell,
/// within a few cells, and a feature answer on a few slice pairs is a few
/// pixels' keypoints: on real crops both stopped short of the right pose,
/// 0.35-1.7 m and 3-7 deg off it, where the right pose landed 13-48 % more.
/// (T, offset) itself, landed, where nothing uphill lands more.
DensePose uphill(const SliceStack& target, const SliceStack& source, const Rigid2D& T, int offset,
                 const DenseSearchParams& params = {});
/// uphill with `land`, the two stacks' lander (pose_lander.hpp) the caller
/// has prepared already: one preparation serves every step of every climb on them.
DensePose uphill(const PoseLander& land, const Rigid2D& T, int offset, int threads = 1);

}  // namespace tomomap
