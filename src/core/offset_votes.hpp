#pragma once
// Which height offsets are worth matching, without matching every slice pair:
// each source descriptor looks up the target descriptors that look like it in
// an index over the whole target map, and every look-alike is a vote for the
// height offset between the two slices. Matching every pair costs n_target x
// n_source slice pairs of brute force; the look-ups cost about one pass over
// the source's descriptors.
#include <cstdint>
#include <vector>

#include "features.hpp"

namespace tomomap {

/// Votes per height offset (target slice index - source slice index).
struct OffsetVotes {
  int first_offset = 0;         ///< the offset of votes[0]
  std::vector<uint64_t> votes;  ///< one per offset from first_offset up

  int lastOffset() const { return first_offset + static_cast<int>(votes.size()) - 1; }
  uint64_t at(int offset) const {
    const long i = static_cast<long>(offset) - first_offset;
    return i < 0 || i >= static_cast<long>(votes.size()) ? 0 : votes[static_cast<size_t>(i)];
  }
  /// Offsets whose votes are the most within `radius` offsets either side and
  /// at least `share` of the most votes anywhere, most votes first, at most `count`.
  std::vector<int> peaks(int radius, double share, size_t count) const;
};

/// Each source descriptor votes for the offsets of the target descriptors
/// within a Hamming radius of it that share one 16-bit chunk with it (a
/// multi-index hash: a close pair shares at least one chunk exactly more often
/// than not), one vote split evenly among them: a descriptor on a plain wall,
/// alike across every slice, says little about height; one on a table's edge,
/// much. Chunks shared by very many descriptors are not followed, for the
/// same reason and to bound the cost. Deterministic for any thread count.
OffsetVotes voteHeightOffsets(const MapFeatures& target, const MapFeatures& source, int threads);

}  // namespace tomomap
