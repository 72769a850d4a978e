#pragma once
// Step 1 of matching (ALGORITHM.md section 4): every (target, source) slice
// pair's descriptor matches and its robust 2D rigid estimate.
#include <cstdint>
#include <utility>
#include <vector>

#include "match_params.hpp"
#include "rigid2d.hpp"

namespace tomomap {

/// One slice pair's outcome; `ok` is false when it gave no estimate.
struct PairEstimate {
  bool ok = false;
  Rigid2D T;
  uint32_t inliers = 0;
};

/// Every slice pair of two maps, row-major (target slice a, source slice b at
/// a * ns + b). The mutual matches are kept, as compact index pairs (source
/// feature, target feature), so that refinement reuses them instead of
/// matching the winning offset's slices again.
struct SlicePairTable {
  size_t nt = 0, ns = 0;
  std::vector<PairEstimate> estimates;
  std::vector<std::vector<std::pair<uint16_t, uint16_t>>> matches;

  size_t index(size_t a, size_t b) const { return a * ns + b; }
};

/// Mutual nearest neighbours in Hamming distance between two slices' descriptors,
/// as matched map-frame positions (source -> target).
Correspondences matchSlices(const SliceFeatures& target, const SliceFeatures& source);

/// Matches and estimates every slice pair, in parallel on matchThreads(params)
/// threads. Each pair's RANSAC is seeded from its indices, so the result does
/// not depend on scheduling.
SlicePairTable estimateSlicePairs(const MapFeatures& target, const MapFeatures& source, const MatchParams& params,
                                  const Progress& progress);

/// The stored matches of slice pair (a, b) as map-frame positions.
Correspondences correspondencesOf(const SlicePairTable& table, const MapFeatures& target, const MapFeatures& source,
                                  size_t a, size_t b);

/// RANSAC settings for one slice pair of maps at `params.grid`.
RansacParams ransacParams(const MatchParams& params);

}  // namespace tomomap
