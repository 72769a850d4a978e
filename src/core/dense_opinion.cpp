#include "dense_opinion.hpp"

#include <chrono>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <utility>

#include "dense_refine.hpp"
#include "height_offsets.hpp"
#include "pose_lander.hpp"

namespace tomomap {
namespace {

/// What one dense search found, its poses' offsets in the map's own slices.
struct Opinion {
  DenseSearch search;
  int pooling = 1;       ///< the map's slices per slice searched
  ConsensusParams same;  ///< when two poses are the same, at that cell

  bool found() const { return search.searched && !search.poses.empty(); }
  const DensePose& best() const { return search.poses.front(); }
  double nextScore() const { return search.poses.size() > 1 ? search.poses[1].score() : 0.0; }
};

/// The search on a raster twice as fine: it reaches maps twice as large (LiDAR crops).
DenseSearchParams wideSearch() {
  DenseSearchParams dp;
  dp.coarse_side = kWideCoarseSide;
  dp.min_coarsening = kWideMinCoarsening;
  return dp;
}

/// Which of `own`'s slices is slice 0 of `searched` (`own`'s occupancy, its
/// full slices, or pooled by `pooling`), the lower of a pooled slice's two.
int firstSlice(const SliceStack& searched, const SliceStack& own, int pooling) {
  return static_cast<int>(std::lround((searched.grid.z_min - own.grid.z_min) / own.grid.cell - 0.5 * (pooling - 1)));
}

/// Searches `t` and `s` (the maps' occupancy, its full slices, or those
/// pooled by `pooling`) with `dp`, and brings the best pose back to the maps'
/// own grid: its offset in their slices, its transform refined on their cells.
/// `land`, where given, is the lander of `t` and `s` already prepared.
Opinion searchAt(const MapFeatures& target, const MapFeatures& source, const SliceStack& t, const SliceStack& s,
                 int pooling, const MatchParams& params, DenseSearchParams dp = {}, const PoseLander* land = nullptr) {
  if (land && !land->lands(t, s)) throw std::logic_error("searchAt: a lander of other stacks");
  dp = denseSearchParams(params, dp);
  const ConsensusParams same = consensusParams(params, t.grid.cell);
  Opinion o{land ? searchDensely(*land, same, source.centre(), dp) : searchDensely(t, s, same, source.centre(), dp),
            pooling, same};
  const int shift = firstSlice(t, target.occupancy, pooling) - firstSlice(s, source.occupancy, pooling);
  for (DensePose& p : o.search.poses) p.offset = p.offset * pooling + shift;
  if (pooling > 1 && !o.search.poses.empty()) {
    DensePose& best = o.search.poses.front();
    DenseRefineParams refine;
    refine.threads = dp.threads;
    best.transform =
        refineOnOccupancy(target.occupancy, source.occupancy, best.offset, best.transform, refine).transform;
  }
  return o;
}

/// Whether the pose `a` at height offset `offset` is `o`'s best pose: the
/// same place at the source's centre, within the smear of height offsets (a
/// pooled offset is a whole number of pooled slices: up to pooling - 1 more).
bool isBestPose(const Opinion& o, const Rigid2D& a, int offset, const MapFeatures& source) {
  return onePlace(a, offset, o.best().transform, o.best().offset, o.same, source.centre(), o.pooling - 1);
}

/// What an opinion says of its own best pose.
DenseEvidence evidenceOf(const Opinion& o) {
  DenseEvidence d;
  d.found = o.found();
  if (!d.found) return d;
  d.best = o.best();
  d.next_score = o.nextScore();
  return d;
}

/// The search that found `o` on `t` and `s` (the target's and the source's
/// occupancy as it searched them) asked again with the maps' roles swapped,
/// its best pose turned back against `o`'s (candidate_decision.hpp).
SecondLook lookAgain(const Opinion& o, const MapFeatures& target, const MapFeatures& source, const SliceStack& t,
                     const SliceStack& s, const MatchParams& params) {
  const Opinion back = searchAt(source, target, s, t, o.pooling, params);
  SecondLook look;
  look.found = back.found();
  if (!look.found) return look;
  const Rigid2D turned = back.best().transform.inverse();
  look.same_place = isBestPose(o, turned, -back.best().offset, source);
  look.apart = (turned.t - o.best().transform.t).norm();
  return look;
}

/// Proposed at most per dense search: its best distinct poses.
constexpr size_t kProposalsPerSearch = 4;

/// The decision's evidence (the searches that reach run here) and its
/// decision: every pose proposed (the features' answer `feature`, their
/// rivals, each dense search's kProposalsPerSearch best) refined and landed
/// as a candidate; each search's second look where the decision asks for it.
CandidateVerdict decide(MatchResult& r, const FeatureProposals& f, const std::optional<Proposal>& feature,
                        const MapFeatures& target, const MapFeatures& source, const MatchParams& params) {
  std::vector<Proposal> proposals;
  if (feature) proposals.push_back(*feature);
  for (const Proposal& p : f.rivals) proposals.push_back(p);
  // The maps' full slices, made where a search or a look needs them.
  std::optional<SliceStack> ft, fs;
  const auto full = [&] {
    if (!ft) ft = fullSlices(target.occupancy), fs = fullSlices(source.occupancy);
  };
  // Each search where it reaches (the wide one, on its finer coarse raster,
  // reaches maps twice as large: LiDAR crops).
  std::optional<Opinion> at_grid, wide, at_pooled;
  if (denseSearchable(target.occupancy) && denseSearchable(source.occupancy)) {
    full();
    at_grid = searchAt(target, source, *ft, *fs, 1, params);
    if (2 * target.grid <= kBars.coarsest_pooled_cell + 1e-9)
      at_pooled = searchAt(target, source, pooled(*ft), pooled(*fs), 2, params);
  }
  // The maps' occupancy prepared once, where something lands poses on it:
  // for the wide search and the candidates.
  std::optional<PoseLander> prepared;
  const auto land = [&]() -> const PoseLander& {
    if (!prepared) prepared.emplace(target.occupancy, source.occupancy, denseSearchParams(params));
    return *prepared;
  };
  if (denseSearchable(target.occupancy, wideSearch()) && denseSearchable(source.occupancy, wideSearch()))
    wide = searchAt(target, source, target.occupancy, source.occupancy, 1, params, wideSearch(), &land());
  DecisionEvidence e;
  e.grid = target.grid;
  e.source_centre = source.occupancy.grid.centre();
  for (const auto& [o, from] :
       {std::pair{&at_grid, Candidate::From::search_at_grid}, std::pair{&wide, Candidate::From::search_wide},
        std::pair{&at_pooled, Candidate::From::search_pooled}}) {
    if (!*o) continue;
    for (size_t i = 0; i < (*o)->search.poses.size() && i < kProposalsPerSearch; ++i)
      proposals.push_back(
          {from, static_cast<int>(i), 0, (*o)->search.poses[i].transform, (*o)->search.poses[i].offset});
    if ((*o)->found())
      e.searches.push_back({from, evidenceOf(**o), (*o)->pooling, {}, from == Candidate::From::search_wide});
  }
  if (!proposals.empty()) e.candidates = refineAndLand(land(), target, source, proposals, params, f.votes);
  // Each search's lead as the decision weighs it.
  for (const SearchLead& l : weighedSearches(e, params))
    (l.from == Candidate::From::search_wide     ? r.dense.wide_lead
     : l.from == Candidate::From::search_pooled ? r.dense.pooled_lead
                                                : r.dense.at_grid_lead) = l.found.lead();
  CandidateVerdict v;
  // The decision asks for the second look of a search on the maps' own
  // cells (at the grid, pooled: those ran on the full slices), one at a time.
  while ((v = decideOnCandidates(e, params)).needs_look) {
    const bool by_pooled = *v.needs_look == Candidate::From::search_pooled;
    const std::optional<Opinion>& o = by_pooled ? at_pooled : at_grid;
    if (!o || !ft) break;  // not a search it can ask (the wide one never answers alone)
    for (SearchLead& l : e.searches)
      if (l.from == *v.needs_look) {
        l.look = by_pooled ? lookAgain(*o, target, source, pooled(*ft), pooled(*fs), params)
                           : lookAgain(*o, target, source, *ft, *fs, params);
        // The look asked last is the one whose search would answer.
        r.dense.second_look_apart = l.look->found ? std::optional<double>(l.look->apart) : std::nullopt;
      }
  }
  r.candidates = std::move(e.candidates);
  return v;
}

/// `r` answered by the decision `v` over r.candidates: the candidate it
/// names, as it judged it.
void answer(MatchResult& r, CandidateVerdict v, const FeatureProposals& f, const MapFeatures& target,
            const MapFeatures& source) {
  r.candidate_verdict = std::move(v);
  r.reliable = r.candidate_verdict->answer >= 0;
  r.reason = r.candidate_verdict->reason;
  if (!r.reliable && !f.missing.empty()) r.reason += (r.candidates.empty() ? ": " : "; the features: ") + f.missing;
  if (r.candidates.empty() &&
      (!denseSearchable(target.occupancy, wideSearch()) || !denseSearchable(source.occupancy, wideSearch())))
    r.reason += "; the maps are too large for a dense search of their occupancy";
  if (!r.reliable) return;
  const Candidate& c = r.candidates[static_cast<size_t>(r.candidate_verdict->answer)];
  r.T_target_source = poseAt(c.landed.transform, c.landed.offset, target, source);
  r.height_offset = c.landed.offset;
  r.answered_by = c.from;
  r.lead_sigma = r.candidate_verdict->lead_sigma;
}

}  // namespace

void settleMatch(MatchResult& r, const FeatureProposals& f, const MapFeatures& target, const MapFeatures& source,
                 const MatchParams& params) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::optional<Proposal> feature =
      r.features.support > 0 ? std::optional<Proposal>(Proposal{Candidate::From::features, 0, r.features.support,
                                                                planar(r.T_target_source), r.height_offset})
                             : std::nullopt;
  answer(r, decide(r, f, feature, target, source, params), f, target, source);
  r.timings.dense = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace tomomap
