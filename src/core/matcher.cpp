#include "matcher.hpp"

#include <algorithm>
#include <chrono>
#include <future>
#include <optional>

#include "dense_opinion.hpp"
#include "height_offsets.hpp"
#include "map_check.hpp"
#include "offset_search.hpp"
#include "pair_cache.hpp"
#include "refine.hpp"
#include "rival_answers.hpp"
#include "text.hpp"
#include "voxel_filter.hpp"

namespace tomomap {
namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

/// Standard deviation of the inliers' positions in target x, y and slice height.
Eigen::Vector3d inlierSpread(const Refined& r) {
  if (r.inliers.empty()) return Eigen::Vector3d::Zero();
  Eigen::Vector3d mean = Eigen::Vector3d::Zero(), sq = Eigen::Vector3d::Zero();
  for (uint32_t i : r.inliers) {
    const Eigen::Vector3d p(r.all.target[i].x(), r.all.target[i].y(), r.heights[i]);
    mean += p;
    sq += p.cwiseProduct(p);
  }
  mean /= static_cast<double>(r.inliers.size());
  return (sq / static_cast<double>(r.inliers.size()) - mean.cwiseProduct(mean)).cwiseMax(0.0).cwiseSqrt();
}

/// The middle of a map's occupancy [m]: its raster's centre, halfway up its slices.
Eigen::Vector3d occupancyCentre(const SliceStack& s) {
  const Eigen::Vector2d c = s.grid.centre();
  return {c.x(), c.y(), s.grid.sliceHeight(s.size() / 2)};
}

/// The 4-DoF transform nearest `T` at `c`: T's yaw, and c moved where T moves
/// it. About the origin instead, the roll and pitch T leaves out would move
/// points far from it (2.8 deg is 1.5 m at 30 m).
Pose4 fourDofAbout(const Eigen::Matrix4d& T, const Eigen::Vector3d& c) {
  Pose4 p = Pose4::fromMatrix(T);
  const Eigen::Vector3d at = T.topLeftCorner<3, 3>() * c + T.topRightCorner<3, 1>();
  const double cy = std::cos(p.yaw), sy = std::sin(p.yaw);
  p.x = at.x() - (cy * c.x() - sy * c.y());
  p.y = at.y() - (sy * c.x() + cy * c.y());
  p.z = at.z() - c.z();
  return p;
}

/// The tomographic match of two maps' feature stacks: its figures and its
/// answer into `r`, what else it proposes into `e`.
void matchSlices(MatchResult& r, FeatureProposals& e, const MapFeatures& target, const MapFeatures& source,
                 const MatchParams& params, const Progress& progress, PairCache* cache) {
  FeatureFindings& f = r.features;
  const size_t nt = target.slices.size(), ns = source.slices.size();
  if (nt < static_cast<size_t>(params.min_support) || ns < static_cast<size_t>(params.min_support)) {
    e.missing = "too few descriptive slices (target " + std::to_string(nt) + ", source " + std::to_string(ns) +
                "; need " + std::to_string(params.min_support) + ")";
    return;
  }
  auto t0 = Clock::now();
  const SlicePairTable pairs = matchSlicePairs(target, source, params, progress, cache);
  if (cache) cache->keep(pairs, params);
  f.slice_pairs = pairs.matchedCount();
  f.slice_pairs_total = nt * ns;
  f.slice_pairs_recalled = pairs.recalled;
  r.timings.pair_matching = secondsSince(t0);

  t0 = Clock::now();
  const std::vector<OffsetScore> scores = scoreOffsets(pairs, target, source, params);
  const OffsetChoice choice = pickOffset(scores, params, source.centre());
  r.timings.consensus = secondsSince(t0);
  if (!choice.best) {
    e.missing = "no slice pair produced an estimate";
    return;
  }
  // The winner, a copy of the right pose where a building's rooms repeat
  // along it, is one proposal among its rivals (distinctAnswers): the
  // decision weighs them all on the occupancy alike.
  const OffsetScore& best = *choice.best;
  f.runner_up_support = choice.runner_up_support;
  f.runner_up_offset = choice.runner_up_offset;
  f.support = static_cast<int>(best.consensus.support());
  f.height_offset = best.offset;
  // Every slice pair's estimate with its source slice and height offset, for the candidates' votes.
  struct Vote {
    int source_slice, offset;
    Rigid2D T;
  };
  std::vector<Vote> estimates;
  for (size_t k = 0; k < pairs.estimates.size(); ++k)
    if (pairs.matched[k] && pairs.estimates[k].ok)
      estimates.push_back({source.slices[k % ns].index, target.slices[k / ns].index - source.slices[k % ns].index,
                           pairs.estimates[k].T});
  e.votes = [estimates = std::move(estimates), same = consensusParams(params, target.grid), centre = source.centre(),
             n = source.occupancy.size()](const Rigid2D& T, int offset) {
    std::vector<int> by_slice(static_cast<size_t>(n), 0);
    for (const Vote& v : estimates)
      if (v.source_slice < n && onePlace(v.T, v.offset, T, offset, same, centre))
        ++by_slice[static_cast<size_t>(v.source_slice)];
    return by_slice;
  };
  int rank = 0;
  for (const OffsetScore& a : distinctAnswers(pairs, target, source, params))
    if (!sameAnswer(a, best, params, source.centre()))
      e.rivals.push_back({Candidate::From::feature_rival, ++rank, static_cast<int>(a.consensus.support()),
                          a.consensus.mean, a.offset});
  for (size_t k : best.consensus.supporters)
    f.supporters.push_back({target.slices[k / ns].index, source.slices[k % ns].index, pairs.estimates[k].inliers});
  std::stable_sort(f.supporters.begin(), f.supporters.end(),
                   [](const SupportingPair& x, const SupportingPair& y) { return x.inliers > y.inliers; });

  t0 = Clock::now();
  const Refined refined = refineOffset(pairs, target, source, best.offset, best.consensus.mean, params);
  r.timings.refinement = secondsSince(t0);

  // The features' answer, proposed to the decision (dense_opinion.hpp).
  r.T_target_source = poseAt(refined.T, best.offset, target, source);
  r.height_offset = best.offset;
  f.inliers = refined.inliers.size();
  f.inlier_spread = inlierSpread(refined);
}

}  // namespace

namespace {

/// Why a map whose up is not trusted (Tilt::upTrusted) cannot be levelled by it.
std::string untrustedUp(const Tilt& tilt) {
  if (tilt.angle > kMaxLevelable) return "too far to level (limit " + fixed(degrees(kMaxLevelable), 0) + " deg)";
  return "too far to level by its planes alone (beyond " + fixed(degrees(kClassCone), 0) +
         " deg its walls may pass for floors, and its lines do not tell them apart: " +
         (tilt.lines < kMinLines ? std::to_string(tilt.lines) + " lines, too few"
                                 : "only " + std::to_string(tilt.standing_lines) + " of its " +
                                       std::to_string(tilt.lines) + " lines stand along that up") +
         ")";
}

}  // namespace

std::optional<std::string> tiltRefusal(const MapFeatures& map, const std::string& role, const MatchParams& params) {
  const Tilt& tilt = map.tilt;
  if (map.leveled || !tilt.measured || tilt.angle <= params.max_tilt) return std::nullopt;
  // Levelling on, a map whose up is trusted but was not levelled was not
  // measured better than it leans: within kClassCone it is matched as it is
  // (thinned or noisy LiDAR crops whose ground lies 1.5-2.3 deg off read
  // 3.5-9.4 deg, their halves disagreeing by as much); beyond it, leaning
  // that far whatever its parts read, it is refused. Levelling off
  // (--no-level), only a map surely beyond the tolerance is refused.
  const bool as_it_is = params.level ? !tilt.beyond_cone : tilt.mayBeWithin(params.max_tilt);
  if (tilt.upTrusted() && as_it_is) return std::nullopt;
  const std::string tilted = role + " map is tilted " + fixed(degrees(tilt.angle), 1) + " +- " +
                             fixed(degrees(tilt.uncertainty), 1) + " deg from gravity (matched as it is up to " +
                             fixed(degrees(params.max_tilt), 1) + " deg)";
  const std::string remedy = "give its up (--up-target, --up-source; the daemon's map_up)";
  if (!tilt.upTrusted())
    return tilted + ", " + untrustedUp(tilt) + ": its axes may be swapped (y up); fix its frame, or " + remedy;
  if (!params.level) return tilted + "; levelling is off: level the map first";
  return tilted + ", not measured better than it leans (its parts read it that far apart): " + remedy;
}

MapFeatures describeMap(const Points& map, const MatchParams& params, StageTimings* timings, size_t* filtered_points,
                        const MapFeatures* previous, const std::optional<Eigen::Vector3d>& up) {
  if (previous && previous->leveled) previous = nullptr;  // its cubes and raster were the levelled map's
  StageTimings local;
  StageTimings& t = timings ? *timings : local;
  const int threads = matchThreads(params);
  // The tilt is measured beside the voxel filter and slicing (it reads the raw
  // points alone, and took as long as both on a street): the map is sliced
  // before the tilt is known, and sliced again in the rare case it is levelled.
  // From the raw points: the filter's grid would bias a leaning plane's normals towards the axes.
  std::future<Tilt> tilt_estimate = std::async(threads > 1 && !up ? std::launch::async : std::launch::deferred, [&] {
    return up ? givenTilt(*up) : estimateTilt(map, params.grid, params.max_tilt);
  });
  auto t0 = Clock::now();
  Eigen::Vector3f corner = previous ? previous->voxel_corner : Eigen::Vector3f::Constant(NAN);
  Points filtered = voxelFilter(map, params.grid, &corner);
  t.voxel += secondsSince(t0);
  t0 = Clock::now();
  SliceStack stack =
      makeSlices(filtered, params.grid, threads, previous ? &previous->occupancy : nullptr, params.sparsest_slice);
  const Tilt tilt = tilt_estimate.get();
  // Only a map that would be refused: levelling a level map by the estimate's
  // own error (0.6 deg on demo-pcd1) cost 3 cm and 0.6 deg on demo-room. A
  // known up has no error: the map is levelled by whatever it leans.
  const bool known = tilt.cue == Tilt::Cue::given;
  const bool level = params.level && (known ? tilt.angle > 0.0 : tilt.angle > params.max_tilt && tilt.levelable());
  if (level) {
    // The levelled map is filtered again: rotated voxels no longer sit on the grid.
    filtered = voxelFilter(rotatePoints(filtered, tilt.leveling()), params.grid);
    stack = makeSlices(filtered, params.grid, threads, nullptr, params.sparsest_slice);
  }
  if (filtered_points) *filtered_points = filtered.size();
  t.slicing += secondsSince(t0);
  t0 = Clock::now();
  MapFeatures f = extractFeatures(std::move(stack), params.features, threads, level ? nullptr : previous);
  f.voxel_corner = corner;
  t.features += secondsSince(t0);
  f.tilt = tilt;
  f.leveled = level;
  return f;
}

MatchResult resultFor(const MapFeatures& target, const MapFeatures& source) {
  MatchResult r;
  r.target_slices = target.slice_count;
  r.source_slices = source.slice_count;
  r.target_features = target.featureCount();
  r.source_features = source.featureCount();
  r.target_tilt = target.tilt.measured ? target.tilt.angle : -1.0;
  r.source_tilt = source.tilt.measured ? source.tilt.angle : -1.0;
  return r;
}

MatchResult matchFeatures(const MapFeatures& target, const MapFeatures& source, const MatchParams& params,
                          const Progress& progress, PairCache* cache) {
  MatchResult r = resultFor(target, source);
  auto tilted = tiltRefusal(target, "target", params);
  if (!tilted) tilted = tiltRefusal(source, "source", params);
  if (tilted) {
    r.reason = std::move(*tilted);
    return r;
  }
  if (std::abs(target.grid - source.grid) > 1e-9)
    throw InputError("feature sets use different grid sizes (" + std::to_string(target.grid) + " and " +
                     std::to_string(source.grid) + " m)");
  FeatureProposals e;
  matchSlices(r, e, target, source, params, progress, cache);
  settleMatch(r, e, target, source, params);
  Eigen::Matrix4d answer = r.T_target_source.matrix();  // between the levelled frames
  SixDofFinishParams finish;
  finish.threads = matchThreads(params);
  if (r.reliable && params.finish) {
    // The finish works on what the daemon has of a peer's map too: its
    // occupancy (empty there where the slices came without it: not held).
    const auto t0 = Clock::now();
    r.finish = finishSixDof(target.occupancy, source.occupancy, answer, finish);
    r.timings.finish = secondsSince(t0);
    if (r.finish->held) {
      answer = r.finish->T_target_source;
      r.T_target_source = fourDofAbout(answer, occupancyCentre(source.occupancy));
    }
  }
  if (target.leveled || source.leveled || (r.finish && r.finish->held))
    r.T_target_source_6dof = betweenOwnFrames(answer, target.slicedUp(), source.slicedUp());
  return r;
}

MatchResult matchMaps(const Points& target, const Points& source, const MatchParams& params, const Progress& progress) {
  if (!(params.grid > 0.0) || !std::isfinite(params.grid)) throw InputError("grid size must be a positive number");
  validateMap(target, "target map");
  validateMap(source, "source map");
  StageTimings t;
  const MapFeatures ft = describeMap(target, params, &t);
  if (progress) progress("features", 1, 2);
  const MapFeatures fs = describeMap(source, params, &t);
  if (progress) progress("features", 2, 2);
  MatchResult r = matchFeatures(ft, fs, params, progress);
  r.timings.takeDescription(t);
  return r;
}

}  // namespace tomomap
