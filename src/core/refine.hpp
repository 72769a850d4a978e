#pragma once
// Step 4 of matching: the winning offset's transform refined over every
// correspondence that agrees with it, then densely on the occupied cells.
#include <vector>

#include "slice_pairs.hpp"

namespace tomomap {

struct Refined {
  Rigid2D T;
  Correspondences all;            ///< the correspondences of the winning offset and its neighbours
  std::vector<double> heights;    ///< target slice height of each of them [m]
  std::vector<uint32_t> inliers;  ///< indices into `all` consistent with T
};

/// One least-squares fit over the stored correspondences of every slice pair at
/// `offset` and its neighbours (walls look alike one slice up or down) that
/// agree with `initial`. Per-slice estimates each carry their own yaw noise,
/// which far from the origin becomes translation error; the joint fit averages
/// it out. Then the dense step, when both maps' occupancy is at hand.
Refined refineOffset(const SlicePairTable& table, const MapFeatures& target, const MapFeatures& source, int offset,
                     const Rigid2D& initial, const MatchParams& params);

}  // namespace tomomap
