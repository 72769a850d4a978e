#include "dense_opinion.hpp"

#include <algorithm>
#include <chrono>

#include "dense_refine.hpp"
#include "dense_search.hpp"
#include "height_offsets.hpp"
#include "text.hpp"

namespace tomomap {
namespace {

/// The dense search's winner must have this many times the telling cells of
/// its best other pose. Room pairs (synth -w room, seeds 1-10, every noise, g
/// 0.1 and 0.05): wrong winners led by 1.00-1.33, right ones by 1.04-3.37;
/// 38 of the 54 right ones lead by 1.4 or more (docs/results.md, "Small rooms").
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
/// Pooled occupancy is searched only where its cell stays this fine [m]:
/// rooms were answered more often at g 0.1 than at 0.05 (5 cm of wall noise
/// splits a wall across two 5 cm cells), and pooling 0.05 m cells to 0.1 m
/// answered 63 more of 400 room pairs, none wrong; pooling 0.1 m cells to
/// 0.2 m answered 2 of the 137 room pairs refused at g 0.1.
constexpr double kCoarsestPooledCell = 0.1;

/// What one dense search found, its poses' offsets in the map's own slices.
struct Opinion {
  DenseSearch search;
  double cell = 0;       ///< of the occupancy searched [m]
  int pooling = 1;       ///< the map's slices per slice searched
  ConsensusParams same;  ///< when two poses are the same, at that cell
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

/// Settles `r` on the opinion `o`: confirms, refuses or replaces a feature
/// answer, or answers a refused match (see consultDenseSearch).
void decide(MatchResult& r, const Opinion& o, const MapFeatures& target, const MapFeatures& source,
            const MatchParams& params) {
  const DenseSearch& d = o.search;
  if (!d.searched || d.poses.empty()) return;
  const DensePose& best = d.poses.front();
  const size_t next = d.poses.size() > 1 ? d.poses[1].telling_inliers : 0;
  r.dense_lead = static_cast<double>(best.telling_inliers) / static_cast<double>(std::max<size_t>(next, 1));
  r.dense_cell = o.cell;
  const auto leadsBy = [&](double lead) { return r.dense_lead >= lead && best.support >= params.min_support; };
  const bool clear = leadsBy(kDenseLead);
  if (r.reliable) {
    const Rigid2D features{r.T_target_source.yaw, {r.T_target_source.x, r.T_target_source.y}};
    // A pooled offset is a whole number of pooled slices: up to pooling - 1 more apart.
    const bool same_pose = std::abs(best.offset - r.height_offset) <= kSmearSlices / 2 + o.pooling - 1 &&
                           agree(features, best.transform, o.same, source.centre());
    if (leadsBy(kDenseOpinion) && same_pose) return;  // confirmed
    if (!clear) {
      r.reliable = false;
      if (!leadsBy(kDenseOpinion))
        r.reason = "a dense search of the occupancy does not confirm the features' answer (its best pose leads by " +
                   fixed(r.dense_lead, 2) + "x with " + std::to_string(best.support) + " slices; need " +
                   fixed(kDenseOpinion, 2) + "x and " + std::to_string(params.min_support) + ")";
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
                "x, need " + fixed(kDenseLead, 2) + "x)";
    return;
  }
  r.method = "dense";
  r.reliable = true;
  r.reason.clear();
  r.T_target_source = {best.transform.t.x(), best.transform.t.y(),
                       target.z_min - source.z_min + best.offset * target.grid, wrapAngle(best.transform.yaw)};
  r.height_offset = best.offset;
  r.support = best.support;
  r.runner_up_support = d.poses.size() > 1 ? d.poses[1].support : 0;
  r.runner_up_offset = d.poses.size() > 1 ? d.poses[1].offset : 0;
  r.supporters.clear();
  r.inliers = best.inliers;
  r.inlier_spread = Eigen::Vector3d::Zero();
}

}  // namespace

void consultDenseSearch(MatchResult& r, const MapFeatures& target, const MapFeatures& source,
                        const MatchParams& params) {
  // A feature answer that leads its runner-up by as many slice pairs as a
  // strong winner has needs no second opinion (and its maps, no extra
  // 0.1-0.9 s): demo-room leads 29 to 1; of the room answers the check
  // overturned, the widest lead was 15 to 5.
  if (r.reliable && !weakWinner(r.support - r.runner_up_support, params)) return;
  const auto t0 = std::chrono::steady_clock::now();
  const auto seconds = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  const MatchResult from_features = r;
  decide(r, searchAt(target, source, target.occupancy, source.occupancy, 1, params), target, source, params);
  if (r.reliable || !denseSearchable(target.occupancy) || 2 * target.grid > kCoarsestPooledCell + 1e-9) {
    r.timings.dense = seconds();
    return;
  }
  // The pooled search judges the features' answer afresh; where it finds no
  // answer either, the reason stays the one from the map's own grid.
  MatchResult at_grid = std::move(r);
  r = from_features;
  decide(r, searchAt(target, source, pooled(target.occupancy), pooled(source.occupancy), 2, params), target, source,
         params);
  if (!r.reliable) {
    if (r.dense_lead > 0)  // the pooled search ran
      at_grid.reason +=
          "; at " + fixed(r.dense_cell, 2) + " m cells its best pose leads by " + fixed(r.dense_lead, 2) + "x";
    r = std::move(at_grid);
  }
  r.timings.dense = seconds();
}

}  // namespace tomomap
