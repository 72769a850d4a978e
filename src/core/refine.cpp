#include "refine.hpp"

#include <cstdlib>

#include "dense_refine.hpp"

namespace tomomap {

Refined refineOffset(const SlicePairTable& table, const MapFeatures& target, const MapFeatures& source, int offset,
                     const Rigid2D& initial, const MatchParams& params) {
  Refined r;
  for (size_t a = 0; a < table.nt; ++a)
    for (size_t b = 0; b < table.ns; ++b) {
      if (std::abs(target.slices[a].index - source.slices[b].index - offset) > 1) continue;
      const Correspondences c = correspondencesOf(table, target, source, a, b);
      r.all.source.insert(r.all.source.end(), c.source.begin(), c.source.end());
      r.all.target.insert(r.all.target.end(), c.target.begin(), c.target.end());
      r.heights.insert(r.heights.end(), c.size(), target.sliceHeight(target.slices[a].index));
    }
  const double threshold = ransacParams(params).inlier_threshold;
  // Up to 10 rounds; inliers may shrink (the consensus mean is only a start).
  RigidEstimate est = refineLeastSquares(r.all, {initial, collectInliers(r.all, initial, threshold)}, threshold,
                                         {10, /*allow_shrinking=*/true});
  r.T = est.transform;
  r.inliers = std::move(est.inliers);
  // The dense step (see dense_refine.hpp).
  if (!target.occupancy.cells.empty() && !source.occupancy.cells.empty()) {
    DenseRefineParams dense;
    dense.threads = matchThreads(params);
    r.T = refineOnOccupancy(target.occupancy, source.occupancy, offset, r.T, dense).transform;
    r.inliers = collectInliers(r.all, r.T, threshold);
  }
  return r;
}

}  // namespace tomomap
