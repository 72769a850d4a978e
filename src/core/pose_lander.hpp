#pragma once
// The two maps' occupancy prepared once, and poses landed on it: how every
// pose a match weighs is judged (a candidate, a climb's step, a search's best
// pose), on one measure, DensePose::score().
#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <utility>
#include <vector>

#include "bit_raster.hpp"
#include "dense_refine.hpp"
#include "dense_search.hpp"

namespace tomomap {

/// The height offset (target slice index - source slice index) within `reach`
/// slices of `middle` at which `T` lands the most source cells within
/// inlier_radius_cells of a target cell; `middle` where none lands more. The
/// dense search places each of its poses by the same count (the first of the
/// most within one coarse cell of height).
int occupancyHeightOffset(const SliceStack& target, const SliceStack& source, const Rigid2D& T, int middle, int reach,
                          const DenseSearchParams& params = {});

/// The pose (T, offset) judged as the search judges its poses (inliers, telling
/// cells both ways, what it contradicts), without searching or refining: for a
/// pose found otherwise, such as the features' answer. Of a partial stack
/// (SliceStack::partial) the slices whose cells it holds land; the others
/// land nothing and enclose no empty space, so that what the pose
/// contradicts there is a part of what it would contradict on the whole map.
DensePose landPose(const SliceStack& target, const SliceStack& source, const Rigid2D& T, int offset,
                   const DenseSearchParams& params = {});

/// How a pose lands one source slice's cells on the target (landPose's counts, slice by slice).
struct SliceLanding {
  int slice = 0;         ///< source slice index
  uint32_t cells = 0;    ///< its occupied cells
  uint32_t telling = 0;  ///< of them, telling (pose_judge.hpp, cellsOf)
  uint32_t seen = 0;     ///< landing where the target saw anything, at any height
  uint32_t on = 0;       ///< landing on target cells (within inlier_radius_cells)
  uint32_t telling_on = 0;
  uint32_t contradicted = 0;  ///< telling cells landing in space the target saw empty
};

/// Each pose (T, offset) landed slice by slice, the source's cells on the
/// target alone (the candidates' landings, candidates.hpp). PoseLander::slices
/// with the stacks prepared once.
std::vector<std::vector<SliceLanding>> landSlices(const SliceStack& target, const SliceStack& source,
                                                  const std::vector<std::pair<Rigid2D, int>>& poses,
                                                  const DenseSearchParams& params = {});

namespace dense_detail {
/// What a pose is judged on, built once per pair of maps (pose_judge.hpp).
struct PoseJudge;
}  // namespace dense_detail

/// The two maps' occupancy prepared once for judging and refining poses on
/// it, for a caller that does so again and again (a climb, nearby_poses.hpp; a
/// dense search and the candidates on the same maps: preparing it took a
/// tenth of a room pair's match at 0.05 m cells, each time). The stacks must
/// outlive it.
class PoseLander {
 public:
  using Poses = std::vector<std::pair<Rigid2D, int>>;  ///< (T, offset) each
  PoseLander(const SliceStack& target, const SliceStack& source, const DenseSearchParams& params = {});
  /// Each pose landed (landPose).
  std::vector<DensePose> operator()(const Poses& poses) const;
  /// What scores() counted and landed, kept for a caller that scores poses
  /// near those it scored last (a climb, nearby_poses.hpp: a step in height
  /// scores the same transforms again, and two thirds of the same poses).
  /// A pose is counted once, and the transforms of the last call are landed
  /// once: it holds their landings alone, a few MB.
  class Memo {
   public:
    using Key = std::array<uint64_t, 3>;                           ///< a transform's bits: yaw, x, y
    using Landed = std::pair<std::vector<int>, std::vector<int>>;  ///< where a transform lands cells forth and back

   private:
    friend class PoseLander;
    const void* of_ = nullptr;  ///< the judge whose counts it holds: a memo handed to another lander starts empty
    std::map<std::pair<Key, int>, double> scored_;
    std::map<Key, std::shared_ptr<const Landed>> landed_;
  };
  /// Each pose's DensePose::score() alone, counted on the telling cells alone
  /// (the only ones it weighs): for a caller that ranks many poses and lands
  /// only the best (a climb, nearby_poses.hpp). With `memo`, what it holds
  /// of these poses is taken from it, and what it counts kept in it: the
  /// same scores to the bit.
  std::vector<double> scores(const Poses& poses, Memo* memo = nullptr) const;
  /// Each pose landed slice by slice (landSlices).
  std::vector<std::vector<SliceLanding>> slices(const Poses& poses) const;
  /// occupancyHeightOffset on the occupancy prepared.
  int heightOffset(const Rigid2D& T, int middle, int reach) const;
  /// Whether it was prepared of `target` and `source` (the very stacks).
  bool lands(const SliceStack& target, const SliceStack& source) const;
  /// refineOnOccupancy on the same two stacks (dense_refine.hpp), prepared with them.
  const OccupancyRefiner& refiner() const;

 private:
  friend DenseSearch searchDensely(const PoseLander& land, const ConsensusParams& same, const Eigen::Vector2d& pivot,
                                   const DenseSearchParams& params);
  std::shared_ptr<const dense_detail::PoseJudge> judge_;
  struct Refiner;  ///< made when first asked for: a landing alone needs none
  std::shared_ptr<Refiner> refine_;
  /// The target's dilated slices down its columns; null on maps the wide search does not reach.
  std::shared_ptr<const BitColumns> columns_;
  int threads_ = 1;
};

/// landPose with a lander: (T, offset) landed.
DensePose landPose(const PoseLander& land, const Rigid2D& T, int offset);

}  // namespace tomomap
