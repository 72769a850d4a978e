#pragma once
// Steps 2 and 3 of matching (docs/algorithm.md): the consensus of
// the slice-pair estimates at every height offset, and the winning offset.
#include <cstdlib>
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

/// When two estimates are one answer, on occupancy of `cell` metres (the
/// maps' grid, or a pooled cell): consensus_translation_cells of them, and consensus_yaw.
ConsensusParams consensusParams(const MatchParams& params, double cell);

/// Whether `a` is the stronger score: more support, then more inliers.
bool outranks(const OffsetScore& a, const OffsetScore& b);

/// One score per height offset that has at least one estimate, by offset:
/// its largest consensus group. With `groups` > 1, then the largest group of
/// the estimates left, and so on, while a group has two supporters or more
/// (another answer at the same offset: a building's rooms repeat along it).
std::vector<OffsetScore> scoreOffsets(const SlicePairTable& table, const MapFeatures& target, const MapFeatures& source,
                                      const MatchParams& params, int groups = 1);

/// Within this many slices of the winner, an offset whose consensus has the
/// winner's own transform is that alignment smeared over height (walls look
/// alike a few slices up or down), not another answer.
constexpr int kSmearSlices = 10;

/// Whether two poses, each at its height offset [slices], are one place:
/// `same` accepts their transforms at `pivot`, and their offsets lie within
/// half the smear of heights, and `slack` slices more (an offset counted in
/// pooled slices is a whole number of them).
inline bool onePlace(const Rigid2D& a, int a_offset, const Rigid2D& b, int b_offset, const ConsensusParams& same,
                     const Eigen::Vector2d& pivot, int slack = 0) {
  return std::abs(a_offset - b_offset) <= kSmearSlices / 2 + slack && agree(a, b, same, pivot);
}

struct OffsetChoice {
  const OffsetScore* best = nullptr;  ///< most support, then most inliers; null when there are no scores
  /// The best other answer: an offset more than one step from the winner that
  /// is either beyond kSmearSlices or has a transform the winner's consensus
  /// would not accept (a wrong hypothesis repeated over a few similar slices).
  int runner_up_support = 0;
  int runner_up_offset = 0;  ///< its height offset [slices]
};

/// `source_centre` is where transforms are compared (see agree()).
OffsetChoice pickOffset(const std::vector<OffsetScore>& scores, const MatchParams& params,
                        const Eigen::Vector2d& source_centre);

}  // namespace tomomap
