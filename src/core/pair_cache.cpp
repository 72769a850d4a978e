#include "pair_cache.hpp"

#include <cstring>

#include "hamming.hpp"

namespace tomomap {
namespace {

/// splitmix64's finaliser: every input bit reaches every output bit.
uint64_t mix(uint64_t x) {
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

uint64_t combine(uint64_t h, uint64_t word) { return mix(h ^ (word + 0x9E3779B97F4A7C15ull)); }

template <typename T>
uint64_t bitsOf(T value) {
  uint64_t w = 0;
  std::memcpy(&w, &value, sizeof value);
  return w;
}

/// What a pair's outcome depends on besides its slices.
uint64_t settingsKey(const MatchParams& p) {
  uint64_t h = combine(0, bitsOf(p.grid));
  h = combine(h, bitsOf(p.ransac_threshold_cells));
  h = combine(h, static_cast<uint64_t>(p.ransac_iterations));
  h = combine(h, bitsOf(p.ransac_confidence));
  return combine(h, static_cast<uint64_t>(p.min_matches));
}

}  // namespace

uint64_t sliceKey(const SliceFeatures& s) {
  uint64_t h = combine(0, s.keypoints.size());
  for (const auto& k : s.keypoints) h = combine(h, bitsOf(k.x()) << 32 | bitsOf(k.y()));
  for (uint64_t w : descriptorWords(s.descriptors)) h = combine(h, w);
  return h;
}

uint64_t pairSeed(uint64_t target_key, uint64_t source_key) { return combine(mix(target_key), source_key); }

size_t PairCache::KeyHash::operator()(const std::pair<uint64_t, uint64_t>& k) const {
  return static_cast<size_t>(k.first ^ mix(k.second));
}

bool PairCache::recall(SlicePairTable& table, size_t k, const MatchParams& params) const {
  if (outcomes_.empty() || settings_ != settingsKey(params)) return false;
  const auto it = outcomes_.find({table.target_keys[k / table.ns], table.source_keys[k % table.ns]});
  if (it == outcomes_.end()) return false;
  table.estimates[k] = it->second.estimate;
  table.matches[k] = it->second.matches;
  table.matched[k] = 1;
  return true;
}

void PairCache::keep(const SlicePairTable& table, const MatchParams& params) {
  outcomes_.clear();
  settings_ = settingsKey(params);
  for (size_t k = 0; k < table.matched.size(); ++k)
    if (table.matched[k])
      outcomes_[{table.target_keys[k / table.ns], table.source_keys[k % table.ns]}] = {table.estimates[k],
                                                                                       table.matches[k]};
}

}  // namespace tomomap
