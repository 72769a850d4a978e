#include "paper_consensus.hpp"

#include <chrono>

#include "core/height_offsets.hpp"
#include "core/lead_sigma.hpp"
#include "core/offset_search.hpp"

namespace tomomap::baseline {

MatchResult matchPaperConsensus(const Points& target, const Points& source, MatchParams params) {
  params.exhaustive = true;     // the paper visits every slice pair once
  params.level = false;         // and takes the maps as they are
  params.sparsest_slice = 0.5;  // cells, where the paper counts width + height points (paper_consensus.hpp)
  StageTimings timings;
  const MapFeatures t = describeMap(target, params, &timings), s = describeMap(source, params, &timings);
  MatchResult r = resultFor(t, s);
  r.timings = timings;
  if (t.slices.empty() || s.slices.empty()) {
    r.reason = "a map has no descriptive slice";
    return r;
  }
  const auto t0 = std::chrono::steady_clock::now();
  const SlicePairTable pairs = matchSlicePairs(t, s, params, {});
  r.features.slice_pairs = pairs.matchedCount();
  r.features.slice_pairs_total = t.slices.size() * s.slices.size();
  const std::vector<OffsetScore> scores = scoreOffsets(pairs, t, s, params);
  const OffsetChoice choice = pickOffset(scores, params, s.centre());
  r.timings.pair_matching = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!choice.best) {
    r.reason = "no slice pair produced an estimate";
    return r;
  }
  // The winning offset's consensus: the mean of its agreeing estimates.
  const OffsetScore& best = *choice.best;
  r.reliable = true;
  FeatureFindings& f = r.features;
  f.support = static_cast<int>(best.consensus.support());
  f.runner_up_support = choice.runner_up_support;
  f.runner_up_offset = choice.runner_up_offset;
  f.height_offset = r.height_offset = best.offset;
  r.lead_sigma = significance(f.support, f.runner_up_support);
  r.T_target_source = poseAt(best.consensus.mean, best.offset, t, s);
  return r;
}

}  // namespace tomomap::baseline
