#pragma once
// Which slice pairs to match: every one (exhaustive), or those at the height
// offsets a descriptor index votes for (offset_votes.hpp), widened until the
// best and the next-best answer each stand among matched neighbours.
#include "slice_pairs.hpp"

namespace tomomap {

/// The slice pairs matched for `target` and `source` as `params.exhaustive` asks.
/// Indexed: the pairs around the strongest vote peaks and a few pairs of every
/// offset first; then, round by round, the pairs around the winning and the
/// runner-up offset (height_offsets.hpp) and every offset whose sample
/// promises a rival to the winner, until none is left unmatched. The winner's
/// consensus and refinement then see exactly the pairs the exhaustive search
/// would give them; offsets never completed had samples too weak to matter.
/// Pairs `cache` (may be null) remembers are taken from it instead of matched:
/// the same pairs are chosen and the same outcomes found either way.
SlicePairTable matchSlicePairs(const MapFeatures& target, const MapFeatures& source, const MatchParams& params,
                               const Progress& progress, const PairCache* cache = nullptr);

}  // namespace tomomap
