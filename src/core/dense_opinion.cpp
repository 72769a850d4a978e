#include "dense_opinion.hpp"

#include <algorithm>
#include <chrono>

#include "dense_refine.hpp"
#include "dense_search.hpp"
#include "pose_evidence.hpp"
#include "height_offsets.hpp"
#include "text.hpp"

namespace tomomap {
namespace {

/// The dense search's winner must score this many times its best other
/// pose. Room pairs (synth -w room, seeds 1-10, every noise, g 0.1 and 0.05),
/// ranked by telling cells alone: wrong winners led by 1.00-1.33, right ones
/// by 1.04-3.37; 38 of the 54 right ones lead by 1.4 or more (docs/results.md,
/// "Small rooms"). With empty space read (seeds 1-100, low and high noise, g
/// 0.1; and pooled from g 0.05), wrong winners led by at most 1.14.
constexpr double kDenseLead = 1.4;
/// A feature answer on a small map stands only where the dense search's best
/// pose is this far ahead of its next (with `min_support` slices) and is the
/// same pose; a best pose that far ahead elsewhere refuses it (or, at
/// kDenseLead, replaces it), and so does one too close to its next to tell.
/// Of 820 room pairs (seeds 1-200 at low and high noise, 1-10 noise-free;
/// g 0.1 and 0.05) the features answered 33, 10 of them wrong: the dense
/// search confirmed none of the 10 (its best pose elsewhere, or at most 1.08x
/// ahead) and 17 of the 23 right ones (1.22x and more). docs/results.md,
/// "Small rooms".
constexpr double kDenseOpinion = 1.2;
/// Pooled occupancy is searched only where its cell stays this fine [m]
/// (maps at g 0.1 and finer): room pairs were measured up to there.
constexpr double kCoarsestPooledCell = 0.2;
/// Where neither search answers alone, the map's grid and pooled occupancy
/// agreeing on a best pose is an answer when the grid's leads by
/// kDenseOpinion and the pooled one by this. On the 304 room pairs (of 820)
/// neither answered alone, the wrong poses both agreed on led by at most
/// 1.19x and 1.08x (docs/results.md, "Small rooms").
constexpr double kPooledAgreement = 1.1;

/// Whether a pose is consistent over at least `min_support` slices.
bool holds(const DensePose& p, const MatchParams& params) { return holdsOver(p, params.min_support); }

/// What one dense search found, its poses' offsets in the map's own slices.
struct Opinion {
  DenseSearch search;
  double cell = 0;       ///< of the occupancy searched [m]
  int pooling = 1;       ///< the map's slices per slice searched
  ConsensusParams same;  ///< when two poses are the same, at that cell

  bool found() const { return search.searched && !search.poses.empty(); }
  const DensePose& best() const { return search.poses.front(); }
  /// The best pose's score over its next's (found() only); 0 where even the
  /// best contradicts more than it finds.
  double lead() const {
    const double next = search.poses.size() > 1 ? search.poses[1].score() : 0;
    return best().score() <= 0 ? 0 : best().score() / std::max(next, 1.0);
  }
  /// The best pose's telling cells in the other map's empty space, per one
  /// landed on its occupancy (found() only).
  double contradiction() const { return tomomap::contradiction(best()); }
  /// Whether the best pose contradicts no more than kMostContradicted (found() only).
  bool consistent() const { return tomomap::consistent(best()); }
  /// The best pose's score over its next's in standard deviations of the
  /// difference of two counts (found() only): a lead on a handful of cells is
  /// chance.
  double significance() const {
    return tomomap::significance(best().score(), search.poses.size() > 1 ? search.poses[1].score() : 0.0);
  }
  /// Whether the best pose leads by `by`, beyond chance, and holds (found() only, else false).
  bool leadsBy(double by, const MatchParams& params) const {
    return found() && lead() >= by && significance() >= kSignificant && holds(best(), params);
  }
  /// What keeps the best pose from counting however far it leads, if anything.
  std::string contradictionNote() const {
    if (!found() || consistent()) return "";
    return "; it lands " + fixed(100 * contradiction(), 0) +
           " % as many telling cells in space the other map saw empty as on its occupancy (at most " +
           fixed(100 * kMostContradicted, 0) + " %)";
  }
};

/// Searches `target` and `source` (the maps' occupancy, or both pooled by
/// `pooling`), and brings the best pose back to the maps' own grid: its
/// offset in their slices, its transform refined on their cells.
Opinion searchAt(const MapFeatures& target, const MapFeatures& source, const SliceStack& t, const SliceStack& s,
                 int pooling, const MatchParams& params) {
  DenseSearchParams dp;
  dp.threads = matchThreads(params);
  const ConsensusParams same{params.consensus_translation_cells * t.grid.cell, params.consensus_yaw};
  Opinion o{searchDensely(t, s, same, source.centre(), dp), t.grid.cell, pooling, same};
  for (DensePose& p : o.search.poses) p.offset *= pooling;
  if (pooling > 1 && !o.search.poses.empty()) {
    DensePose& best = o.search.poses.front();
    best.transform = refineOnOccupancy(target.occupancy, source.occupancy, best.offset, best.transform).transform;
  }
  return o;
}

/// Whether the pose `a` at height offset `offset` is `o`'s best pose: the
/// same place at the source's centre, within the smear of height offsets (a
/// pooled offset is a whole number of pooled slices: up to pooling - 1 more).
bool isBestPose(const Opinion& o, const Rigid2D& a, int offset, const MapFeatures& source) {
  return std::abs(o.best().offset - offset) <= kSmearSlices / 2 + o.pooling - 1 &&
         agree(a, o.best().transform, o.same, source.centre());
}

/// Whether the searches at the map's grid and on pooled occupancy, each short
/// of a clear pose, pick the same one, the grid's as far ahead as confirming
/// a feature answer needs and the pooled one kPooledAgreement ahead.
bool corroborate(const Opinion& grid, const Opinion& pooled, const MapFeatures& source, const MatchParams& params) {
  return grid.leadsBy(kDenseOpinion, params) && pooled.leadsBy(kPooledAgreement, params) &&
         isBestPose(pooled, grid.best().transform, grid.best().offset, source);
}

/// `r` answered by the opinion's best pose (`method` "dense").
void answer(MatchResult& r, const Opinion& o, const MapFeatures& target, const MapFeatures& source) {
  const DenseSearch& d = o.search;
  const DensePose& best = o.best();
  r.method = "dense";
  r.reliable = true;
  r.reason.clear();
  r.dense_lead = o.lead();
  r.dense_cell = o.cell;
  r.T_target_source = {best.transform.t.x(), best.transform.t.y(), heightShift(target, source, best.offset),
                       wrapAngle(best.transform.yaw)};
  r.height_offset = best.offset;
  r.support = best.support;
  r.runner_up_support = d.poses.size() > 1 ? d.poses[1].support : 0;
  r.runner_up_offset = d.poses.size() > 1 ? d.poses[1].offset : 0;
  r.supporters.clear();
  r.inliers = best.inliers;
  r.inlier_spread = Eigen::Vector3d::Zero();
}

/// Settles `r` on the opinion `o`: confirms, refuses or replaces a feature
/// answer, or answers a refused match (see consultDenseSearch).
void decide(MatchResult& r, const Opinion& o, const MapFeatures& target, const MapFeatures& source,
            const MatchParams& params) {
  if (!o.found()) return;
  const DensePose& best = o.best();
  r.dense_lead = o.lead();
  r.dense_cell = o.cell;
  const bool clear = o.leadsBy(kDenseLead, params);
  if (r.reliable) {
    const Rigid2D features = planar(r.T_target_source);
    // A search whose best pose contradicts what the other map saw empty found
    // no place of its own for the maps; the features' pose is then judged the
    // way the search judges its poses, and stands if it holds. On the
    // full-size building at g 0.2 (seeds 1-5, the raster coarsened for maps
    // this large) the search's best poses contradicted 53-73 %; the features'
    // right poses 1.8 and 2.6 %, their wrong ones (8.7-8.8 m along the
    // building) 66-90 %.
    if (!o.consistent()) {
      const DensePose own = landPose(target.occupancy, source.occupancy, features, r.height_offset);
      if (holds(own, params)) return;  // confirmed by its own landing
    }
    const bool same_pose = isBestPose(o, features, r.height_offset, source);
    if (o.leadsBy(kDenseOpinion, params) && same_pose) return;  // confirmed
    if (!clear) {
      r.reliable = false;
      if (!o.leadsBy(kDenseOpinion, params))
        r.reason = "a dense search of the occupancy does not confirm the features' answer (its best pose leads by " +
                   fixed(r.dense_lead, 2) + "x with " + std::to_string(best.support) + " slices; need " +
                   fixed(kDenseOpinion, 2) + "x and " + std::to_string(params.min_support) + ")" +
                   o.contradictionNote();
      else
        r.reason = "the features and a dense search of the occupancy disagree (" + fixed(r.dense_lead, 2) +
                   "x lead for a pose " + fixed((best.transform.t - features.t).norm(), 2) + " m, " +
                   fixed(degrees(std::abs(wrapAngle(best.transform.yaw - features.yaw))), 1) + " deg and " +
                   fixed(std::abs(best.offset - r.height_offset) * target.grid, 2) + " m in height away)";
      return;
    }
    // A clear dense pose elsewhere replaces the features' answer, as it
    // replaces a refused one: on the 820 room pairs it did so 11 times, each
    // right (0.003-0.105 m off), where the features had led by a few pairs.
  } else if (!clear) {
    r.reason += "; nor did a dense search of the occupancy find a clear pose (lead " + fixed(r.dense_lead, 2) +
                "x, need " + fixed(kDenseLead, 2) + "x)" + o.contradictionNote();
    return;
  }
  answer(r, o, target, source);
}

/// consultDenseSearch's work on a match it does not skip.
void settle(MatchResult& r, const MapFeatures& target, const MapFeatures& source, const MatchParams& params) {
  const Opinion at_grid = searchAt(target, source, target.occupancy, source.occupancy, 1, params);
  decide(r, at_grid, target, source, params);
  if (r.reliable || !at_grid.found() || 2 * target.grid > kCoarsestPooledCell + 1e-9) return;
  // The pooled search answers with a clear pose, or with the grid's where the
  // two agree; it does not confirm the features' answer: on a held-out room
  // (seed 203, high noise, g 0.05) it confirmed one 0.27 m off in height,
  // within the smear a confirmation allows.
  const Opinion at_pooled = searchAt(target, source, pooled(target.occupancy), pooled(source.occupancy), 2, params);
  if (!at_pooled.found()) return;
  r.dense_pooled_lead = at_pooled.lead();
  if (at_pooled.leadsBy(kDenseLead, params))
    answer(r, at_pooled, target, source);
  else if (corroborate(at_grid, at_pooled, source, params))
    answer(r, at_grid, target, source);
  else
    r.reason += "; at " + fixed(at_pooled.cell, 2) + " m cells its best pose leads by " +
                fixed(r.dense_pooled_lead, 2) + "x" + at_pooled.contradictionNote();
}

/// A small map's answer at the height offset where most of the source's
/// occupancy lands on the target's, within the smear of offsets around its
/// own: the features' offset is the smear's centre (height_offsets.hpp).
/// On noisy rooms the height was up to 0.18 m off, this one's up to 0.06 m;
/// on 7 of 29 demo-room moves one or two slices off, this one's within 1 mm
/// (docs/results.md, "Height from occupancy"). Larger maps keep theirs.
void takeOccupancyHeight(MatchResult& r, const MapFeatures& target, const MapFeatures& source) {
  if (!denseSearchable(target.occupancy) || !denseSearchable(source.occupancy)) return;
  r.height_offset = occupancyHeightOffset(target.occupancy, source.occupancy, planar(r.T_target_source),
                                          r.height_offset, kSmearSlices / 2);
  r.T_target_source.z = heightShift(target, source, r.height_offset);
}

}  // namespace

void consultDenseSearch(MatchResult& r, const MapFeatures& target, const MapFeatures& source,
                        const MatchParams& params) {
  // A feature answer that leads its runner-up by as many slice pairs as a
  // strong winner has needs no second opinion (and its maps, no extra
  // 0.1-0.9 s): demo-room leads 29 to 1; of the room answers the check
  // overturned, the widest lead was 15 to 5.
  const auto t0 = std::chrono::steady_clock::now();
  if (!r.reliable || weakWinner(r.support - r.runner_up_support, params)) settle(r, target, source, params);
  if (r.reliable) takeOccupancyHeight(r, target, source);
  r.timings.dense = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace tomomap
