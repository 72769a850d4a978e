#include "dense_opinion.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <tuple>

#include "dense_refine.hpp"
#include "dense_search.hpp"
#include "height_offsets.hpp"
#include "nearby_poses.hpp"

namespace tomomap {
namespace {

/// What one dense search found, its poses' offsets in the map's own slices.
struct Opinion {
  DenseSearch search;
  double cell = 0;       ///< of the occupancy searched [m]
  int pooling = 1;       ///< the map's slices per slice searched
  ConsensusParams same;  ///< when two poses are the same, at that cell

  bool found() const { return search.searched && !search.poses.empty(); }
  const DensePose& best() const { return search.poses.front(); }
  double nextScore() const { return search.poses.size() > 1 ? search.poses[1].score() : 0.0; }
};

/// The search on a raster twice as fine, for a thin feature answer (verdict.hpp).
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
Opinion searchAt(const MapFeatures& target, const MapFeatures& source, const SliceStack& t, const SliceStack& s,
                 int pooling, const MatchParams& params, DenseSearchParams dp = {}) {
  dp.threads = matchThreads(params);
  const ConsensusParams same = consensusParams(params, t.grid.cell);
  Opinion o{searchDensely(t, s, same, source.centre(), dp), t.grid.cell, pooling, same};
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

/// The verdict's view of an opinion, its best pose against the features'
/// answer in `r` where there is one.
DenseEvidence evidenceOf(const Opinion& o, const MatchResult& r, bool features, const MapFeatures& target,
                         const MapFeatures& source) {
  DenseEvidence d;
  d.found = o.found();
  d.cell = o.cell;
  if (!d.found) return d;
  d.best = o.best();
  d.next_score = o.nextScore();
  if (features) {
    const Rigid2D f = planar(r.T_target_source);
    d.at_features = isBestPose(o, f, r.height_offset, source);
    d.apart = (d.best.transform.t - f.t).norm();
    d.apart_yaw = std::abs(wrapAngle(d.best.transform.yaw - f.yaw));
    d.apart_height = std::abs(d.best.offset - r.height_offset) * target.grid;
  }
  return d;
}

/// The search that found `o` on `t` and `s` (the target's and the source's
/// occupancy as it searched them) asked again with the maps' roles swapped,
/// its best pose turned back against `o`'s (verdict.hpp).
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

/// `r` answered by the opinion's best pose.
void answer(MatchResult& r, const Opinion& o, const MapFeatures& target, const MapFeatures& source) {
  const DensePose& best = o.best();
  r.T_target_source = poseAt(best.transform, best.offset, target, source);
  r.height_offset = best.offset;
}

/// `r`'s pose moved uphill on the maps' occupancy (nearby_poses.hpp, with
/// `land`, a lander of it), where that lands more telling cells. The climb
/// starts from `r`'s pose, or from whichever of `found` (each search's best
/// pose, the features' answer) at its place lands more beyond chance: within
/// the smear of heights and within looksApart at the source raster's
/// centre. Searches on other rasters and slices stop on different hilltops
/// of one place, and a climb from the lower one can stay there: on a real
/// RGB-D crop (sunrgbd-room-164, g 0.05) the search at the grid (full slices) answered 0.28 m along two walls,
/// landing 1,129 telling cells on every slice; the wide search's pose, 0.26 m
/// from it, landed 1,297 (3.4 sigma more) and lay 0.06 m from the truth
/// (climbed from it, the answer is 0.11 m off). A start that lands more
/// within chance is no better: on a room (seed 14, high noise, g 0.05) one
/// landing 5,724 against the answer's 5,688 climbed to 0.27 m off, not 0.13.
void climbUphill(MatchResult& r, const PoseLander& land, const std::vector<std::pair<Rigid2D, int>>& found,
                 const MapFeatures& target, const MapFeatures& source, const MatchParams& params) {
  const Rigid2D answer = planar(r.T_target_source);
  ConsensusParams same = consensusParams(params, target.grid);
  same.translation_tolerance = looksApart(params, target.grid);
  std::vector<std::pair<Rigid2D, int>> starts{{answer, r.height_offset}};
  for (const auto& [T, offset] : found)
    if (onePlace(T, offset, answer, r.height_offset, same, source.occupancy.grid.centre()))
      starts.emplace_back(T, offset);
  const std::vector<DensePose> landed = land(starts);
  const DensePose* start = &landed.front();
  for (const DensePose& p : landed)
    if (p.score() > start->score() && significance(p.score(), landed.front().score()) >= kBars.significant) start = &p;
  const DensePose top = uphill(land, OccupancyRefiner(target.occupancy, source.occupancy), start->transform,
                               start->offset, matchThreads(params));
  r.T_target_source = poseAt(top.transform, top.offset, target, source);
  r.height_offset = top.offset;
}

/// A small map's answer at the height offset where most of the source's
/// occupancy lands on the target's, within the smear of offsets around its
/// own: the features' offset is the smear's centre (height_offsets.hpp).
/// On noisy rooms the height was up to 0.18 m off, this one's up to 0.06 m;
/// on 7 of 29 demo-room moves one or two slices off, this one's within 1 mm
/// (docs/results.md, "Height from occupancy"). Larger maps keep theirs.
/// `land`, where the answer climbed, is the climb's lander: the occupancy
/// it prepared is the one this height is read on.
void takeOccupancyHeight(MatchResult& r, const MapFeatures& target, const MapFeatures& source, const PoseLander* land) {
  if (!denseSearchable(target.occupancy) || !denseSearchable(source.occupancy)) return;
  const Rigid2D T = planar(r.T_target_source);
  r.height_offset =
      land ? land->heightOffset(T, r.height_offset, kSmearSlices / 2)
           : occupancyHeightOffset(target.occupancy, source.occupancy, T, r.height_offset, kSmearSlices / 2);
  r.T_target_source.z = heightShift(target, source, r.height_offset);
}

/// Proposed at most per dense search: its best distinct poses.
constexpr size_t kProposalsPerSearch = 4;

/// Every pose proposed (the features' distinct answers, each dense search's
/// kProposalsPerSearch best) refined and landed into r.candidates
/// (MatchParams::candidates). The searches the verdict ran are taken as
/// they are; the ones it did not ask for run here.
void allCandidates(MatchResult& r, const Evidence& e, const std::optional<Proposal>& feature,
                   std::optional<Opinion> at_grid, std::optional<Opinion> wide, std::optional<Opinion> at_pooled,
                   const MapFeatures& target, const MapFeatures& source, const MatchParams& params) {
  std::vector<Proposal> proposals;
  if (feature) proposals.push_back(*feature);
  for (const Proposal& p : e.feature_rivals) proposals.push_back(p);
  // The maps' full slices, made where a search or a look needs them.
  std::optional<SliceStack> ft, fs;
  const auto full = [&] {
    if (!ft) ft = fullSlices(target.occupancy), fs = fullSlices(source.occupancy);
  };
  // Each search where it reaches (the wide one, on its finer coarse raster,
  // reaches maps twice as large: LiDAR crops).
  if (denseSearchable(target.occupancy) && denseSearchable(source.occupancy)) {
    if (!at_grid) full(), at_grid = searchAt(target, source, *ft, *fs, 1, params);
    if (!at_pooled && 2 * target.grid <= kBars.coarsest_pooled_cell + 1e-9)
      full(), at_pooled = searchAt(target, source, pooled(*ft), pooled(*fs), 2, params);
  }
  if (!wide && denseSearchable(target.occupancy, wideSearch()) && denseSearchable(source.occupancy, wideSearch()))
    wide = searchAt(target, source, target.occupancy, source.occupancy, 1, params, wideSearch());
  // Each search's poses proposed; what it says of its own best pose, for the
  // decision; its lead, as the verdict's path records it, where it did not ask for it.
  std::vector<SearchLead> leads;
  for (const auto& [o, from, lead] : {std::tuple{&at_grid, Candidate::From::search_at_grid, &r.dense.at_grid_lead},
                                      std::tuple{&wide, Candidate::From::search_wide, &r.dense.wide_lead},
                                      std::tuple{&at_pooled, Candidate::From::search_pooled, &r.dense.pooled_lead}}) {
    if (!*o) continue;
    for (size_t i = 0; i < (*o)->search.poses.size() && i < kProposalsPerSearch; ++i)
      proposals.push_back(
          {from, static_cast<int>(i), 0, (*o)->search.poses[i].transform, (*o)->search.poses[i].offset});
    if (!(*o)->found()) continue;
    leads.push_back({from, evidenceOf(**o, r, false, target, source), (*o)->pooling, {}});
    if (*lead == 0) *lead = leads.back().found.lead();
  }
  r.candidates = refineAndLand(target, source, proposals, params, e.feature_votes);
  // The decision asks for a search's second look where that would decide.
  for (;;) {
    r.candidate_verdict = decideOnCandidates(r.candidates, params, target.grid, source.occupancy.grid.centre(), leads);
    if (!r.candidate_verdict->needs_look) break;
    const Candidate::From which = *r.candidate_verdict->needs_look;
    full();
    for (SearchLead& l : leads)
      if (l.from == which) {
        l.look = which == Candidate::From::search_pooled
                     ? lookAgain(*at_pooled, target, source, pooled(*ft), pooled(*fs), params)
                     : lookAgain(*at_grid, target, source, *ft, *fs, params);
        if (l.look->found && !r.dense.second_look_apart) r.dense.second_look_apart = l.look->apart;
      }
  }
}

/// `r` answered by the decision over the candidates (allCandidates): the
/// candidate it names, as it judged it.
void answerByCandidates(MatchResult& r, const Evidence& e, const MapFeatures& target, const MapFeatures& source) {
  const CandidateVerdict& v = *r.candidate_verdict;
  r.reliable = v.answer >= 0;
  r.reason = v.reason;
  if (!r.reliable && !e.features.missing.empty())
    r.reason += (r.candidates.empty() ? ": " : "; the features: ") + e.features.missing;
  if (r.candidates.empty() &&
      (!denseSearchable(target.occupancy, wideSearch()) || !denseSearchable(source.occupancy, wideSearch())))
    r.reason += "; the maps are too large for a dense search of their occupancy";
  if (!r.reliable) return;
  const Candidate& c = r.candidates[static_cast<size_t>(v.answer)];
  r.T_target_source = poseAt(c.landed.transform, c.landed.offset, target, source);
  r.height_offset = c.landed.offset;
  r.answered_by = c.from;
  r.lead_sigma = v.lead_sigma;
}

}  // namespace

void settleMatch(MatchResult& r, Evidence& e, const MapFeatures& target, const MapFeatures& source,
                 const MatchParams& params) {
  const auto t0 = std::chrono::steady_clock::now();
  const bool features = r.features.support > 0;  // the features proposed an answer (judged or not)
  const std::optional<Proposal> feature =
      features ? std::optional<Proposal>(Proposal{Candidate::From::features, 0, r.features.support,
                                                  planar(r.T_target_source), r.height_offset})
               : std::nullopt;
  std::optional<Opinion> at_grid, wide, at_pooled;
  if (params.decision == Decision::candidates) {
    if (!e.tilted.empty()) {
      r.reliable = false, r.reason = e.tilted;
    } else {
      allCandidates(r, e, feature, at_grid, wide, at_pooled, target, source, params);
      answerByCandidates(r, e, target, source);
    }
    r.timings.dense = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return;
  }
  // The searches that answer alone search the full slices alone (kFullSlice);
  // the pooled stacks are kept for the pooled pose's second look.
  std::optional<SliceStack> full_target, full_source, pooled_target, pooled_source;
  const auto full = [&] {
    if (!full_target) full_target = fullSlices(target.occupancy), full_source = fullSlices(source.occupancy);
  };
  Verdict v;
  while ((v = decideMatch(e, params)).needs != Verdict::Needs::nothing) {
    switch (v.needs) {
      case Verdict::Needs::search_at_grid:
        full();
        at_grid = searchAt(target, source, *full_target, *full_source, 1, params);
        e.at_grid = evidenceOf(*at_grid, r, features, target, source);
        if (at_grid->found()) r.dense.at_grid_lead = e.at_grid->lead();
        break;
      case Verdict::Needs::wide_search:
        wide = searchAt(target, source, target.occupancy, source.occupancy, 1, params, wideSearch());
        e.wide = evidenceOf(*wide, r, features, target, source);
        if (wide->found()) r.dense.wide_lead = e.wide->lead();
        break;
      case Verdict::Needs::features_landed:
        e.features_landed = landPose(target.occupancy, source.occupancy, planar(r.T_target_source), r.height_offset);
        break;
      case Verdict::Needs::pooled_search:
        full();
        pooled_target = pooled(*full_target);
        pooled_source = pooled(*full_source);
        at_pooled = searchAt(target, source, *pooled_target, *pooled_source, 2, params);
        e.pooled = evidenceOf(*at_pooled, r, features, target, source);
        e.pooled->at_grid_best = e.pooled->found && at_grid && at_grid->found() &&
                                 isBestPose(*at_pooled, at_grid->best().transform, at_grid->best().offset, source);
        if (at_pooled->found()) r.dense.pooled_lead = e.pooled->lead();
        break;
      case Verdict::Needs::second_look:
        e.second_look = v.by == Verdict::By::pooled
                            ? lookAgain(*at_pooled, target, source, *pooled_target, *pooled_source, params)
                            : lookAgain(*at_grid, target, source, *full_target, *full_source, params);
        if (e.second_look->found) r.dense.second_look_apart = e.second_look->apart;
        break;
      case Verdict::Needs::around_features: {
        const int tolerance = static_cast<int>(params.consensus_translation_cells);
        DenseSearchParams dp;
        dp.threads = matchThreads(params);
        e.around_features = bestAround(target.occupancy, source.occupancy, planar(r.T_target_source), r.height_offset,
                                       tolerance, kBars.around_tolerances * tolerance, dp);
        break;
      }
      case Verdict::Needs::nothing:
        break;
    }
  }
  // The poses the searches found, for the answer's climb (climbUphill).
  std::vector<std::pair<Rigid2D, int>> found;
  if (features) found.emplace_back(planar(r.T_target_source), r.height_offset);
  for (const std::optional<Opinion>* o : {&at_grid, &wide, &at_pooled})
    if (*o && (*o)->found()) found.emplace_back((*o)->best().transform, (*o)->best().offset);
  r.reliable = v.by != Verdict::By::none;
  r.reason = v.reason;
  r.answered_by = answeredBy(v.by);
  r.lead_sigma = r.reliable ? answerLead(e, v.by) : 0.0;
  if (v.by == Verdict::By::at_grid) answer(r, *at_grid, target, source);
  if (v.by == Verdict::By::wide) answer(r, *wide, target, source);
  if (v.by == Verdict::By::pooled) answer(r, *at_pooled, target, source);
  // An answer the occupancy weighed (a dense search found poses) is placed by
  // it too; a clear feature winner, or one on a map too large to search, is
  // placed by its keypoints.
  const bool weighed = (e.at_grid && e.at_grid->found) || (e.wide && e.wide->found);
  // One preparation of the occupancy lands the climb's starts, serves the
  // climb and reads the answer's height.
  std::optional<PoseLander> land;
  if (r.reliable && weighed) {
    DenseSearchParams dp;
    dp.threads = matchThreads(params);
    land.emplace(target.occupancy, source.occupancy, dp);
    climbUphill(r, *land, found, target, source, params);
  }
  if (r.reliable) takeOccupancyHeight(r, target, source, land ? &*land : nullptr);
  if (params.candidates) allCandidates(r, e, feature, at_grid, wide, at_pooled, target, source, params);
  r.timings.dense = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace tomomap
