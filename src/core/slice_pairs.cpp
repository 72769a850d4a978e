#include "slice_pairs.hpp"

#include <algorithm>
#include <atomic>

#include "hamming.hpp"
#include "pair_cache.hpp"
#include "threads.hpp"

namespace tomomap {
namespace {

/// Source and target positions of `matches` (source index, target index).
template <typename Matches>
Correspondences positions(const SliceFeatures& target, const SliceFeatures& source, const Matches& matches) {
  Correspondences c;
  c.source.reserve(matches.size());
  c.target.reserve(matches.size());
  for (const auto& [s, t] : matches) {
    c.source.emplace_back(source.keypoints[static_cast<size_t>(s)].cast<double>());
    c.target.emplace_back(target.keypoints[static_cast<size_t>(t)].cast<double>());
  }
  return c;
}

}  // namespace

int matchThreads(const MatchParams& params) { return resolvedThreads(params.threads); }

RansacParams ransacParams(const MatchParams& p) {
  RansacParams r;
  r.inlier_threshold = p.ransac_threshold_cells * p.grid;
  r.max_iterations = p.ransac_iterations;
  r.confidence = p.ransac_confidence;
  r.min_inliers = std::max(3, p.min_matches / 2);
  return r;
}

Correspondences matchSlices(const SliceFeatures& target, const SliceFeatures& source) {
  return positions(target, source, mutualNearest(source.descriptors, target.descriptors));
}

Correspondences correspondencesOf(const SlicePairTable& table, const MapFeatures& target, const MapFeatures& source,
                                  size_t a, size_t b) {
  return positions(target.slices[a], source.slices[b], table.matches[table.index(a, b)]);
}

SlicePairTable::SlicePairTable(const MapFeatures& target, const MapFeatures& source)
    : nt(target.slices.size()), ns(source.slices.size()), estimates(nt * ns), matches(nt * ns), matched(nt * ns, 0) {
  for (const auto& s : target.slices) target_keys.push_back(sliceKey(s));
  for (const auto& s : source.slices) source_keys.push_back(sliceKey(s));
}

size_t SlicePairTable::matchedCount() const {
  return static_cast<size_t>(std::count(matched.begin(), matched.end(), uint8_t{1}));
}

void estimateSlicePairs(SlicePairTable& table, const std::vector<size_t>& pairs, const MapFeatures& target,
                        const MapFeatures& source, const MatchParams& params, const Progress& progress,
                        const PairCache* cache) {
  std::vector<size_t> todo;  // each pair once, even if listed twice
  std::vector<uint8_t> listed(table.matched);
  for (size_t k : pairs) {
    if (listed[k]) continue;
    listed[k] = 1;
    if (cache && cache->recall(table, k, params))
      ++table.recalled;
    else
      todo.push_back(k);
  }
  const size_t n = todo.size();
  const RansacParams ransac = ransacParams(params);
  std::atomic<size_t> done{0};
  const size_t report_every = std::max<size_t>(1, n / 100);
#pragma omp parallel for schedule(dynamic, 4) num_threads(matchThreads(params))
  for (long long i = 0; i < static_cast<long long>(n); ++i) {
    const size_t k = todo[static_cast<size_t>(i)];
    const size_t a = k / table.ns, b = k % table.ns;
    const auto matches = mutualNearest(source.slices[b].descriptors, target.slices[a].descriptors);
    auto& kept = table.matches[k];
    kept.reserve(matches.size());
    for (const auto& [s, t] : matches) kept.emplace_back(static_cast<uint16_t>(s), static_cast<uint16_t>(t));
    if (matches.size() >= static_cast<size_t>(params.min_matches)) {
      const Correspondences c = positions(target.slices[a], source.slices[b], matches);
      if (auto est = ransacRigid2D(c, ransac, pairSeed(table.target_keys[a], table.source_keys[b])))
        table.estimates[k] = {true, est->transform, static_cast<uint32_t>(est->inliers.size())};
    }
    table.matched[k] = 1;
    const size_t finished = ++done;
    if (progress && finished % report_every == 0) {
#pragma omp critical(tomomap_progress)
      progress("slice pairs", finished, n);
    }
  }
}

SlicePairTable estimateSlicePairs(const MapFeatures& target, const MapFeatures& source, const MatchParams& params,
                                  const Progress& progress, const PairCache* cache) {
  SlicePairTable table(target, source);
  std::vector<size_t> all(table.estimates.size());
  for (size_t k = 0; k < all.size(); ++k) all[k] = k;
  estimateSlicePairs(table, all, target, source, params, progress, cache);
  return table;
}

}  // namespace tomomap
