#pragma once
// Dense refinement of the planar part of a match on the slices' occupied cells.
#include <memory>
#include <vector>

#include "rigid2d.hpp"
#include "slices.hpp"

namespace tomomap {

class BitRaster;

struct DenseRefineParams {
  std::vector<double> radii_cells{3.0, 1.5};  ///< correspondence radius per stage [grid cells]
  int iterations_per_stage = 10;              ///< upper bound; stops earlier once converged
  size_t max_cells = 40000;                   ///< source cells used at most (evenly thinned)
  int threads = 1;                            ///< threads it uses (MatchParams::threads, resolved)
};

struct DenseRefineResult {
  Rigid2D transform;
  size_t correspondences = 0;  ///< cell pairs used in the last iteration
};

/// Feature keypoints sit on whole pixels and vertical structures repeat the same
/// keypoint in many slices, so the feature fit alone leaves a yaw error of a few
/// milliradians: 0.2 m at 50 m from the origin. This ICP over every occupied cell
/// of the slice pairs at `offset` (target index - source index) averages the
/// pixel quantisation out over thousands of cells.
DenseRefineResult refineOnOccupancy(const SliceStack& target, const SliceStack& source, int offset,
                                    const Rigid2D& initial, const DenseRefineParams& params = {});

/// refineOnOccupancy with the target's occupancy prepared once for many
/// refinements of poses on one pair of stacks (a dense search refines a dozen,
/// a climb up to ten): preparing it was most of a refinement's own time. The
/// stacks must outlive it.
class OccupancyRefiner {
 public:
  OccupancyRefiner(const SliceStack& target, const SliceStack& source);
  DenseRefineResult operator()(int offset, const Rigid2D& initial, const DenseRefineParams& params = {}) const;
  const SliceStack& target() const { return target_; }
  const SliceStack& source() const { return source_; }

 private:
  const SliceStack &target_, &source_;
  std::shared_ptr<const std::vector<BitRaster>> bits_;  ///< per target slice
};

}  // namespace tomomap
