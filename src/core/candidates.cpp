#include "candidates.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "dense_refine.hpp"
#include "height_offsets.hpp"
#include "nearby_poses.hpp"

namespace tomomap {
namespace {

/// Distinct places refined at most: a climb lands thousands of poses.
constexpr size_t kMostRefined = 4;

/// A height offset in slices as an offset in slices pooled by two.
int pooledOffset(int offset) { return static_cast<int>(std::floor(offset / 2.0 + 0.5)); }

/// `out` with each candidate's landing, slice by slice (by `land`, the
/// maps' occupancy's lander, and on pooled occupancy for fine maps), its
/// feature votes and its whole transform.
std::vector<Candidate> finished(std::vector<Candidate> out, const PoseLander& land, const MapFeatures& target,
                                const MapFeatures& source, const DenseSearchParams& dp, const FeatureVotes& votes) {
  std::vector<std::pair<Rigid2D, int>> poses, pooled_poses;
  for (const Candidate& c : out) {
    poses.emplace_back(c.landed.transform, c.landed.offset);
    pooled_poses.emplace_back(c.landed.transform, pooledOffset(c.landed.offset));
  }
  std::vector<std::vector<SliceLanding>> slices = land.slices(poses);
  std::vector<std::vector<SliceLanding>> pooled_slices;
  if (target.grid < dp.finest_empty_cell - 1e-9)
    pooled_slices = landSlices(pooled(target.occupancy), pooled(source.occupancy), pooled_poses, dp);
  for (size_t i = 0; i < out.size(); ++i) {
    if (i < slices.size()) out[i].slices = std::move(slices[i]);
    if (i < pooled_slices.size()) out[i].pooled_slices = std::move(pooled_slices[i]);
    if (votes) out[i].feature_votes = votes(out[i].landed.transform, out[i].landed.offset);
    out[i].T_own_frames =
        betweenOwnFrames(poseAt(out[i].landed.transform, out[i].landed.offset, target, source).matrix(),
                         target.slicedUp(), source.slicedUp());
  }
  return out;
}

}  // namespace

const char* fromName(Candidate::From from) {
  switch (from) {
    case Candidate::From::features:
      return "features";
    case Candidate::From::feature_rival:
      return "feature_rival";
    case Candidate::From::search_at_grid:
      return "search_at_grid";
    case Candidate::From::search_wide:
      return "search_wide";
    case Candidate::From::search_pooled:
      return "search_pooled";
  }
  return "?";
}

bool isDenseSearch(Candidate::From from) {
  return from == Candidate::From::search_at_grid || from == Candidate::From::search_wide ||
         from == Candidate::From::search_pooled;
}

std::optional<Candidate::From> fromName(const std::string& name) {
  for (const Candidate::From from :
       {Candidate::From::features, Candidate::From::feature_rival, Candidate::From::search_at_grid,
        Candidate::From::search_wide, Candidate::From::search_pooled})
    if (name == fromName(from)) return from;
  return std::nullopt;
}

std::vector<Candidate> refineAndLand(const MapFeatures& target, const MapFeatures& source,
                                     const std::vector<Proposal>& proposals, const MatchParams& params,
                                     const FeatureVotes& votes) {
  if (proposals.empty()) return {};
  return refineAndLand(PoseLander(target.occupancy, source.occupancy, denseSearchParams(params)), target, source,
                       proposals, params, votes);
}

std::vector<Candidate> refineAndLand(const PoseLander& land, const MapFeatures& target, const MapFeatures& source,
                                     const std::vector<Proposal>& proposals, const MatchParams& params,
                                     const FeatureVotes& votes) {
  if (proposals.empty()) return {};
  const DenseSearchParams dp = denseSearchParams(params);
  std::vector<std::pair<Rigid2D, int>> poses;
  for (const Proposal& p : proposals) poses.emplace_back(p.T, p.offset);
  const std::vector<DensePose> as_proposed = land(poses);
  std::vector<Candidate> out;
  for (size_t i = 0; i < proposals.size(); ++i) {
    const Proposal& p = proposals[i];
    Candidate c;
    c.from = p.from, c.rank = p.rank, c.feature_support = p.feature_support;
    c.proposed = p.T, c.proposed_offset = p.offset;
    c.proposed_landed = c.landed = as_proposed[i];
    out.push_back(std::move(c));
  }
  // The best distinct places as proposed are refined. On maps small enough
  // for a dense search each climbs uphill (nearby_poses.hpp): the pose the
  // score judged lands most near it. On larger maps a climb of single cells
  // took seconds (1,600 landings more on a campus pair), and one ICP on the
  // occupancy from the proposal (dense_refine.hpp) takes a feature answer's
  // pixel-quantised pose where the occupancy says, as a climb would, at a
  // fraction of the time; on small maps the ICP in place of the climb
  // answered fewer right and one wrong (docs/results.md, "Candidates on
  // large maps"). Two proposals are one place within sqrt(2) consensus
  // tolerances at the source's centre and the smear of heights: two looks
  // at one place of equal spread lie sqrt(2) times one's error apart.
  std::vector<size_t> order(out.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return out[a].proposed_landed.score() > out[b].proposed_landed.score(); });
  ConsensusParams same = consensusParams(params, target.grid);
  same.translation_tolerance = std::sqrt(2.0) * same.translation_tolerance;
  const Eigen::Vector2d centre = source.occupancy.grid.centre();
  const bool small = denseSearchable(target.occupancy) && denseSearchable(source.occupancy);
  DenseRefineParams rp;
  rp.threads = dp.threads;
  std::vector<size_t> refined;
  for (size_t i : order) {
    if (refined.size() == kMostRefined) break;
    Candidate& c = out[i];
    const bool seen = std::any_of(refined.begin(), refined.end(), [&](size_t k) {
      return onePlace(out[k].proposed, out[k].proposed_offset, c.proposed, c.proposed_offset, same, centre);
    });
    if (seen) continue;
    refined.push_back(i);
    c.landed = small ? uphill(land, c.proposed, c.proposed_offset, dp.threads)
                     : landPose(land, land.refiner()(c.proposed_offset, c.proposed, rp).transform, c.proposed_offset);
  }
  // Each at the height where most of the source's occupancy lands, within
  // half the smear of heights either side of its own: a climb and the
  // features weigh telling cells alone, and a room's floor and ceiling are
  // not telling. On noisy rooms the features' height was up to 0.18 m off,
  // this one's up to 0.06 m (docs/algorithm.md, "Height from occupancy").
  std::vector<int> heights(out.size());  // found apart, each candidate on a thread of its own
#pragma omp parallel for schedule(dynamic) num_threads(dp.threads)
  for (size_t i = 0; i < out.size(); ++i)
    heights[i] = land.heightOffset(out[i].landed.transform, out[i].landed.offset, kSmearSlices / 2);
  PoseLander::Poses moved;
  std::vector<size_t> which;
  for (size_t i = 0; i < out.size(); ++i)
    if (const DensePose& p = out[i].landed; heights[i] != p.offset)
      moved.emplace_back(p.transform, heights[i]), which.push_back(i);
  const std::vector<DensePose> relanded = land(moved);
  for (size_t k = 0; k < which.size() && k < relanded.size(); ++k) out[which[k]].landed = relanded[k];
  return finished(std::move(out), land, target, source, dp, votes);
}

}  // namespace tomomap
