#include "matcher.hpp"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <map>

#include "dense_refine.hpp"
#include "hamming.hpp"
#include "map_check.hpp"
#include "voxel_filter.hpp"

namespace tomomap {
namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// One slice pair's outcome; `ok` is false when it gave no estimate.
struct PairEstimate {
  bool ok = false;
  Rigid2D T;
  uint32_t inliers = 0;
};

/// The consensus found at one height offset.
struct OffsetScore {
  int offset = 0;            ///< target slice index - source slice index
  Consensus consensus;
  double inlier_sum = 0;     ///< inliers of the supporting pairs
};

RansacParams ransacParams(const MatchParams& p) {
  RansacParams r;
  r.inlier_threshold = p.ransac_threshold_cells * p.grid;
  r.max_iterations = p.ransac_iterations;
  r.confidence = p.ransac_confidence;
  r.min_inliers = std::max(3, p.min_matches / 2);
  return r;
}

}  // namespace

Correspondences matchSlices(const SliceFeatures& target, const SliceFeatures& source) {
  const auto matches = mutualNearest(source.descriptors, target.descriptors);
  Correspondences c;
  c.source.reserve(matches.size());
  c.target.reserve(matches.size());
  for (const auto& [s, t] : matches) {
    c.source.push_back(source.keypoints[static_cast<size_t>(s)].cast<double>());
    c.target.push_back(target.keypoints[static_cast<size_t>(t)].cast<double>());
  }
  return c;
}

MapFeatures describeMap(const Points& map, const MatchParams& params, StageTimings* timings,
                        size_t* filtered_points) {
  StageTimings local;
  StageTimings& t = timings ? *timings : local;
  auto t0 = Clock::now();
  const Points filtered = voxelFilter(map, params.grid);
  t.voxel += secondsSince(t0);
  if (filtered_points) *filtered_points = filtered.size();
  t0 = Clock::now();
  SliceStack stack = makeSlices(filtered, params.grid);
  t.slicing += secondsSince(t0);
  t0 = Clock::now();
  MapFeatures f = extractFeatures(std::move(stack), params.features);
  t.features += secondsSince(t0);
  return f;
}

MatchResult matchFeatures(const MapFeatures& target, const MapFeatures& source, const MatchParams& params,
                          const Progress& progress) {
  MatchResult r;
  r.target_slices = target.slice_count;
  r.source_slices = source.slice_count;
  r.target_features = target.featureCount();
  r.source_features = source.featureCount();
  if (std::abs(target.grid - source.grid) > 1e-9)
    throw InputError("feature sets use different grid sizes (" + std::to_string(target.grid) + " and " +
                     std::to_string(source.grid) + " m)");
  const double g = target.grid;
  const size_t nt = target.slices.size(), ns = source.slices.size();
  if (nt < static_cast<size_t>(params.min_support) || ns < static_cast<size_t>(params.min_support)) {
    r.reason = "too few descriptive slices (target " + std::to_string(nt) + ", source " +
               std::to_string(ns) + "; need " + std::to_string(params.min_support) + ")";
    return r;
  }
  if (params.threads > 0) omp_set_num_threads(params.threads);

  // Section 4: every (target, source) slice pair is estimated exactly once; each
  // belongs to exactly one height offset.
  auto t0 = Clock::now();
  const RansacParams ransac = ransacParams(params);
  r.slice_pairs = nt * ns;
  std::vector<PairEstimate> pairs(nt * ns);
  std::atomic<size_t> done{0};
  const size_t report_every = std::max<size_t>(1, nt * ns / 100);
#pragma omp parallel for schedule(dynamic, 4)
  for (long long k = 0; k < static_cast<long long>(nt * ns); ++k) {
    const size_t a = static_cast<size_t>(k) / ns, b = static_cast<size_t>(k) % ns;
    const Correspondences c = matchSlices(target.slices[a], source.slices[b]);
    if (c.size() >= static_cast<size_t>(params.min_matches)) {
      // Seeded per pair so results do not depend on thread scheduling.
      if (auto est = ransacRigid2D(c, ransac, 0x9E3779B97F4A7C15ull * (a + 1) + b))
        pairs[static_cast<size_t>(k)] = {true, est->transform, static_cast<uint32_t>(est->inliers.size())};
    }
    const size_t n = ++done;
    if (progress && n % report_every == 0) {
#pragma omp critical(tomomap_progress)
      progress("slice pairs", n, nt * ns);
    }
  }
  r.timings.pair_matching = secondsSince(t0);

  // Sections 5 and 6: consensus per height offset, best offset wins.
  t0 = Clock::now();
  std::map<int, std::vector<size_t>> by_offset;
  for (size_t k = 0; k < pairs.size(); ++k)
    if (pairs[k].ok) by_offset[target.slices[k / ns].index - source.slices[k % ns].index].push_back(k);
  ConsensusParams cp;
  cp.translation_tolerance = params.consensus_translation_cells * g;
  cp.yaw_tolerance = params.consensus_yaw;
  std::vector<OffsetScore> scores;
  for (const auto& [offset, members] : by_offset) {
    std::vector<Rigid2D> estimates;
    std::vector<double> weights;
    for (size_t k : members) {
      estimates.push_back(pairs[k].T);
      weights.push_back(pairs[k].inliers);
    }
    OffsetScore s{offset, findConsensus(estimates, cp, weights), 0};
    for (size_t& i : s.consensus.supporters) {
      i = members[i];  // from index into `estimates` to index into `pairs`
      s.inlier_sum += pairs[i].inliers;
    }
    scores.push_back(std::move(s));
  }
  r.timings.consensus = secondsSince(t0);
  if (scores.empty()) {
    r.reason = "no slice pair produced an estimate";
    return r;
  }
  const auto best = std::max_element(scores.begin(), scores.end(), [](const OffsetScore& x, const OffsetScore& y) {
    if (x.consensus.support() != y.consensus.support()) return x.consensus.support() < y.consensus.support();
    return x.inlier_sum < y.inlier_sum;
  });
  for (const auto& s : scores)
    if (std::abs(s.offset - best->offset) > 1)
      r.runner_up_support = std::max(r.runner_up_support, static_cast<int>(s.consensus.support()));
  r.support = static_cast<int>(best->consensus.support());
  r.height_offset = best->offset;
  for (size_t k : best->consensus.supporters)
    r.supporters.push_back({target.slices[k / ns].index, source.slices[k % ns].index, pairs[k].inliers});
  std::stable_sort(r.supporters.begin(), r.supporters.end(),
                   [](const SupportingPair& x, const SupportingPair& y) { return x.inliers > y.inliers; });

  // Refinement: one least-squares fit over every correspondence of the winning
  // offset and its neighbours (walls look alike one slice up or down) that agrees
  // with the consensus. Per-slice estimates each carry their own yaw noise, which
  // far from the origin becomes translation error; the joint fit averages it out.
  t0 = Clock::now();
  Correspondences all;
  std::vector<double> heights;  // target slice height of each correspondence
  for (size_t a = 0; a < nt; ++a)
    for (size_t b = 0; b < ns; ++b) {
      if (std::abs(target.slices[a].index - source.slices[b].index - best->offset) > 1) continue;
      const Correspondences c = matchSlices(target.slices[a], source.slices[b]);
      all.source.insert(all.source.end(), c.source.begin(), c.source.end());
      all.target.insert(all.target.end(), c.target.begin(), c.target.end());
      heights.insert(heights.end(), c.size(), target.sliceHeight(target.slices[a].index));
    }
  Rigid2D T = best->consensus.mean;
  std::vector<uint32_t> inliers = collectInliers(all, T, ransac.inlier_threshold);
  for (int round = 0; round < 10 && inliers.size() >= 2; ++round) {
    const Rigid2D refined = fitRigid2D(all, &inliers);
    auto next = collectInliers(all, refined, ransac.inlier_threshold);
    if (next.size() < 2) break;
    T = refined;
    if (next == inliers) break;
    inliers = std::move(next);
  }
  // Then the dense step, when both maps' occupancy is at hand (see dense_refine.hpp).
  if (!target.occupancy.cells.empty() && !source.occupancy.cells.empty()) {
    const auto dense = refineOnOccupancy(target.occupancy, source.occupancy, best->offset, T);
    T = dense.transform;
    inliers = collectInliers(all, T, ransac.inlier_threshold);
  }
  r.timings.refinement = secondsSince(t0);

  r.T_target_source.x = T.t.x();
  r.T_target_source.y = T.t.y();
  r.T_target_source.yaw = wrapAngle(T.yaw);
  r.T_target_source.z = target.z_min - source.z_min + best->offset * g;
  r.inliers = inliers.size();
  if (!inliers.empty()) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero(), sq = Eigen::Vector3d::Zero();
    for (uint32_t i : inliers) {
      const Eigen::Vector3d p(all.target[i].x(), all.target[i].y(), heights[i]);
      mean += p;
      sq += p.cwiseProduct(p);
    }
    mean /= static_cast<double>(inliers.size());
    r.inlier_spread = (sq / static_cast<double>(inliers.size()) - mean.cwiseProduct(mean)).cwiseMax(0.0).cwiseSqrt();
  }

  if (r.support < params.min_support)
    r.reason = "only " + std::to_string(r.support) + " slice pairs agree (need " +
               std::to_string(params.min_support) + ")";
  else if (r.inliers < static_cast<size_t>(params.min_inliers))
    r.reason = "only " + std::to_string(r.inliers) + " inlier correspondences (need " +
               std::to_string(params.min_inliers) + ")";
  else
    r.reliable = true;
  return r;
}

MatchResult matchMaps(const Points& target, const Points& source, const MatchParams& params,
                      const Progress& progress) {
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
