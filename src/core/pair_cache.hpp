#pragma once
// Slice-pair outcomes remembered by the two slices' content, so that matching
// a map again after an update re-estimates only the pairs whose slices changed.
#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

#include "slice_pairs.hpp"

namespace tomomap {

/// The content key of one slice: its keypoints' positions and descriptors.
/// Equal keys mean equal features (up to a 64-bit hash collision).
uint64_t sliceKey(const SliceFeatures& s);

/// The RANSAC seed of a slice pair: from content, so that an outcome depends
/// neither on where the slices sit in their maps nor on thread scheduling.
uint64_t pairSeed(uint64_t target_key, uint64_t source_key);

/// The outcomes of the pairs matched last time for one pair of maps. A pair's
/// outcome depends only on its two slices' content and the settings (its
/// RANSAC is seeded from the content keys), so an outcome recalled is the one
/// matching again would give.
class PairCache {
 public:
  /// Copies the remembered outcome of the table's pair `k` into it; false when
  /// that content was not matched last time, or was matched with other settings.
  bool recall(SlicePairTable& table, size_t k, const MatchParams& params) const;
  /// Forgets what it held and keeps the matched pairs of `table`.
  void keep(const SlicePairTable& table, const MatchParams& params);
  size_t size() const { return outcomes_.size(); }

 private:
  struct Outcome {
    PairEstimate estimate;
    std::vector<std::pair<uint16_t, uint16_t>> matches;
  };
  struct KeyHash {
    size_t operator()(const std::pair<uint64_t, uint64_t>& k) const;
  };
  uint64_t settings_ = 0;
  std::unordered_map<std::pair<uint64_t, uint64_t>, Outcome, KeyHash> outcomes_;
};

}  // namespace tomomap
