#pragma once
// Steps 2 and 3 of matching (ALGORITHM.md sections 5 and 6): the consensus of
// the slice-pair estimates at every height offset, and the winning offset.
#include <vector>

#include "consensus.hpp"
#include "slice_pairs.hpp"

namespace tomomap {

/// The consensus found at one height offset.
struct OffsetScore {
  int offset = 0;         ///< target slice index - source slice index
  Consensus consensus;    ///< supporters index SlicePairTable::estimates
  double inlier_sum = 0;  ///< inliers of the supporting pairs
};

/// One score per height offset that has at least one estimate, by offset.
std::vector<OffsetScore> scoreOffsets(const SlicePairTable& table, const MapFeatures& target, const MapFeatures& source,
                                      const MatchParams& params);

struct OffsetChoice {
  const OffsetScore* best = nullptr;  ///< most support, then most inliers; null when there are no scores
  int runner_up_support = 0;          ///< best support more than one step away from the winner
  int runner_up_offset = 0;           ///< its height offset [slices]
};

OffsetChoice pickOffset(const std::vector<OffsetScore>& scores);

}  // namespace tomomap
