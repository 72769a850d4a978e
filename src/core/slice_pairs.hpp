#pragma once
// Step 1 of matching (docs/algorithm.md): every (target, source) slice
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

/// The slice pairs of two maps, row-major (target slice a, source slice b at
/// a * ns + b), of which those `matched` hold their outcome (every pair, or
/// only those at the height offsets worth matching: offset_search.hpp). The
/// mutual matches are kept, as compact index pairs (source feature, target
/// feature), so that refinement reuses them instead of matching the winning
/// offset's slices again.
struct SlicePairTable {
  size_t nt = 0, ns = 0;
  std::vector<PairEstimate> estimates;
  std::vector<std::vector<std::pair<uint16_t, uint16_t>>> matches;
  std::vector<uint8_t> matched;                    ///< 1 where the pair has been matched
  std::vector<uint64_t> target_keys, source_keys;  ///< each slice's content key (pair_cache.hpp)
  size_t recalled = 0;                             ///< pairs taken from a PairCache instead of matched

  SlicePairTable() = default;
  /// Nothing matched yet.
  SlicePairTable(const MapFeatures& target, const MapFeatures& source);
  size_t index(size_t a, size_t b) const { return a * ns + b; }
  size_t matchedCount() const;
};

/// Mutual nearest neighbours in Hamming distance between two slices' descriptors,
/// as matched map-frame positions (source -> target).
Correspondences matchSlices(const SliceFeatures& target, const SliceFeatures& source);

class PairCache;

/// Matches and estimates the pairs `pairs` (table indices) that are not matched
/// yet, in parallel on matchThreads(params) threads, taking those `cache`
/// (may be null) remembers instead. Each pair's RANSAC is seeded from its
/// slices' content keys, so the result depends neither on scheduling nor on
/// which other pairs were matched or recalled.
void estimateSlicePairs(SlicePairTable& table, const std::vector<size_t>& pairs, const MapFeatures& target,
                        const MapFeatures& source, const MatchParams& params, const Progress& progress,
                        const PairCache* cache = nullptr);

/// Every slice pair matched and estimated.
SlicePairTable estimateSlicePairs(const MapFeatures& target, const MapFeatures& source, const MatchParams& params,
                                  const Progress& progress, const PairCache* cache = nullptr);

/// The stored matches of slice pair (a, b) as map-frame positions.
Correspondences correspondencesOf(const SlicePairTable& table, const MapFeatures& target, const MapFeatures& source,
                                  size_t a, size_t b);

/// RANSAC settings for one slice pair of maps at `params.grid`.
RansacParams ransacParams(const MatchParams& params);

}  // namespace tomomap
