#pragma once
// What a pose is judged on: each map's cells, which of them tell places
// apart, its occupancy dilated by the inlier radius and the space it saw
// empty; and how a pose's cells are counted on the other map. Shared by the
// lander (pose_lander.hpp) and the dense search (dense_search.cpp), not a
// public interface: dense_detail.
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "bit_raster.hpp"
#include "enclosure.hpp"
#include "pose_lander.hpp"
#include "rigid2d.hpp"
#include "slices.hpp"

namespace tomomap::dense_detail {

/// An occupied cell's centre [m], its slice, and whether it tells places apart.
struct Cell {
  Eigen::Vector2d p;
  int slice;
  bool telling;
};

/// A room's walls, floor and ceiling fit it turned by a half or a quarter turn
/// as well as the right way; what tells the turns apart is everything else.
/// So a cell is "telling" unless its column (with its neighbours within
/// `wall_spread`) is occupied in most slices (a wall) or its slice is mostly
/// occupied (a floor or a ceiling).
std::vector<Cell> cellsOf(const SliceStack& s, double wall_spread);

/// Where `T` puts each of `cells` on the raster `grid`: its pixel's index, or
/// -1 off the raster. The same at every height offset, so found once per pose.
std::vector<int> landings(const std::vector<Cell>& cells, const Rigid2D& T, const SliceGrid& grid);

/// What a pose's cells, landed on the other map, count there (countInliers).
struct Tally {
  size_t inliers = 0, telling = 0;
  int slices = 0;  ///< source slices with at least half their cells on the target
  /// The same, of the cells that land where the target saw anything at any height (`seen`).
  int slices_seen = 0;
  size_t contradicted = 0;  ///< telling cells off the target, in space it encloses (if given)
};

/// How many of the source `cells`, landed at `landing`, fall on the `dilated`
/// target at height `offset` (Tally); telling cells off it count against the
/// pose where `enclosure` encloses them, and `seen`, where given, is where
/// the target saw anything. Slice by slice into `per_slice`, where given.
Tally countInliers(const std::vector<BitRaster>& dilated, const std::vector<Cell>& cells,
                   const std::vector<int>& landing, int offset, int source_slices, const Enclosure* enclosure = nullptr,
                   const BitRaster* seen = nullptr, std::vector<SliceLanding>* per_slice = nullptr);

/// A stack of dilated slices as mostInliersAt reads it, a window of slices
/// down a pixel's column, each slice tested in turn (BitColumns::window).
struct SliceWindows {
  const std::vector<BitRaster>& slices;
  int size() const { return static_cast<int>(slices.size()); }
  uint64_t window(size_t idx, int first, int count) const {
    uint64_t out = 0;
    for (int k = 0; k < count; ++k)
      if (const BitRaster& s = slices[static_cast<size_t>(first + k)]; !s.empty() && s.test(idx))
        out |= uint64_t{1} << k;
    return out;
  }
};

/// The height offset from `lowest` to `lowest + count - 1` (1 <= count <=
/// 64) at which most of the source `cells`, landed at `landing`, fall on a
/// dilated target cell (`dilated`: SliceWindows or BitColumns of the
/// target's dilated slices; countInliers' inliers; the first of the most,
/// or `preferred`, an offset in that range, where it is among them),
/// counted for every offset in one pass over the cells: choosing a height
/// needs the inliers alone, not the rest of a tally.
///
/// A cell's offsets are one window down its column, counted four offsets
/// to a word (kNibbleLanes). On maps a dense search reaches the windows are
/// read off BitColumns: on the slowest matrix pair that took half the time
/// of testing each offset's slice in turn.
///
/// Made for SliceWindows and BitColumns (pose_judge.cpp).
template <typename Columns>
int mostInliersAt(const Columns& dilated, const std::vector<Cell>& cells, const std::vector<int>& landing, int lowest,
                  int count, std::optional<int> preferred = {});

/// `dilated`, the dilated slices of a stack on raster `grid`, by column.
BitColumns columnsOf(const std::vector<BitRaster>& dilated, const SliceGrid& grid);

/// Every slice's occupancy grown by inlier_radius_cells (BitRaster::disk): a
/// cell lands on the stack where its pixel is set.
std::vector<BitRaster> dilatedSlices(const SliceStack& stack, const DenseSearchParams& params);

struct JudgedMap;

/// What a pose is judged on, built once per pair of maps: both maps' dilated
/// occupancy, their cells and the space each saw empty.
struct PoseJudge {
  const SliceStack &target, &source;
  std::vector<BitRaster> dilated, source_dilated;
  std::vector<Cell> source_cells, target_cells;
  std::vector<Cell> source_telling, target_telling;  ///< the telling ones alone: all a score counts
  Enclosure target_encloses, source_encloses;
  BitRaster target_seen;
  const Enclosure *in_target, *in_source;  ///< null on cells too fine to read empty space

  PoseJudge(const SliceStack& t, const SliceStack& s, const DenseSearchParams& params);
  // Its enclosures are pointed at (in_target, in_source): a copy would point at the original's.
  PoseJudge(const PoseJudge&) = delete;
  PoseJudge& operator=(const PoseJudge&) = delete;

  /// The source's cells, landed on the target's raster at `landing`, at
  /// height `offset` (and slice by slice into `per_slice`, if given).
  Tally forth(const std::vector<int>& landing, int offset, std::vector<SliceLanding>* per_slice = nullptr) const {
    return countInliers(dilated, source_cells, landing, offset, source.size(), in_target, &target_seen, per_slice);
  }
  /// The target's cells landed back on the source (at `back`) at height `offset`.
  Tally backwards(const std::vector<int>& back, int offset) const {
    return countInliers(source_dilated, target_cells, back, -offset, target.size(), in_source);
  }
  /// Sets p's tally from the source's cells landed on the target (`there`)
  /// and adds the target's landed back on the source (`here`): both ways.
  static void judge(DensePose& p, const Tally& there, const Tally& here) {
    p.inliers = there.inliers, p.telling_inliers = there.telling + here.telling, p.support = there.slices;
    p.support_seen = there.slices_seen;
    p.contradicted = there.contradicted + here.contradicted;
  }
  void judge(DensePose& p, const Tally& there) const {
    judge(p, there, backwards(landings(target_cells, p.transform.inverse(), source.grid), p.offset));
  }
  /// p's score alone, on the telling cells both ways (what judge gives it).
  double score(const Rigid2D& T, int offset, const std::vector<int>& forth_telling,
               const std::vector<int>& back_telling) const {
    DensePose p{T, offset, 0};
    judge(p, countInliers(dilated, source_telling, forth_telling, offset, source.size(), in_target),
          countInliers(source_dilated, target_telling, back_telling, -offset, target.size(), in_source));
    return p.score();
  }

 private:
  /// The judge of the two maps prepared (judgedMaps), their parts moved in.
  PoseJudge(const SliceStack& t, const SliceStack& s, const DenseSearchParams& params,
            std::pair<JudgedMap, JudgedMap>&& maps);
};

}  // namespace tomomap::dense_detail
