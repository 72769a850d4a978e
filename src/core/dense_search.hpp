#pragma once
// A dense search for small maps: every yaw, shift and height offset scored by
// how much of the two maps' occupancy coincides, without features.
#include <vector>

#include "consensus.hpp"
#include "rigid2d.hpp"
#include "slices.hpp"

namespace tomomap {

struct MatchParams;  // match_params.hpp

struct DenseSearchParams {
  /// The coarse raster has at most this many cells along each axis; the
  /// coarse cell is a whole number of grid cells (at most kMaxCoarsening).
  int coarse_side = 32;
  int min_coarsening = 1;          ///< the coarse cell is at least this many grid cells (kWideCoarseSide)
  double yaw_step = radians(3.0);  ///< [rad]; 3 deg moves a point 3 m out by 0.16 m, under one coarse cell
  int candidates = 12;             ///< distinct coarse poses refined on the full grid
  /// Source cells each coarse pose's ICP uses at most (evenly thinned):
  /// that refinement ranks the search's poses, and each of them, as a
  /// candidate, climbs again on up to DenseRefineParams::max_cells
  /// (nearby_poses.hpp). What a quarter of those
  /// cells changed: docs/results.md, "A search's poses refined on fewer cells".
  size_t refine_cells = 10000;
  double inlier_radius_cells = 1.5;  ///< [grid cells]
  /// How far a scanned wall wanders from slice to slice (range noise either
  /// side) [m]: a wall's column is counted with its neighbours this far.
  double wall_spread = 0.05;
  /// Empty space is read only on cells at least this large [m]: on finer
  /// ones a noisy wall's cells wander beyond inlier_radius_cells and read as
  /// empty. On high-noise room pairs a right pose contradicted 23 % as many
  /// telling cells as it landed at 0.05 m cells (median), 6 % at 0.1 m
  /// (docs/results.md, "Empty space").
  double finest_empty_cell = 0.1;
  int threads = 1;
};

/// `dp` on the threads `params` asks for (matchThreads): how a match runs
/// the dense search and prepares a lander.
DenseSearchParams denseSearchParams(const MatchParams& params, DenseSearchParams dp = {});

/// A map is small enough for the dense search when its coarse cell need not be
/// larger than this many grid cells: the search then stays under a second and
/// its coarse cell under a wall's thickness plus a furniture's width.
constexpr int kMaxCoarsening = 6;

/// The coarse raster's side for the wide search (dense_opinion.cpp): twice
/// the default's cells, so it reaches maps twice as large at the same coarse
/// cell, and its cells on a LiDAR crop (340 cells at g 0.2) are 1.2 m, not
/// 2.2 m, a road's width. Its best pose proposes candidates and corroborates
/// one, but does not answer on its own second look (candidate_decision.cpp).
/// Its coarse cell stays 2 grid cells or more: at 1, on rooms at g 0.1, it
/// cost 2.5 times the usual search and answered no more rooms.
constexpr int kWideCoarseSide = 64;
constexpr int kWideMinCoarsening = 2;

/// A telling cell where the other map saw empty space counts against a pose
/// twice what one landing on occupancy counts for it. Room pairs (seeds
/// 1-100, low and high noise) at g 0.1: the best pose was right and 1.4x
/// ahead of its next on 137 of 200 at weight 0, 197 at 2, 198 at 3 and 4. On
/// occupancy pooled from g 0.05 to 0.1 m, the one wrong best pose (seed 11,
/// one enclosure laid on a like one) led by 1.14x at 2, 1.33x at 3 and 1.68x
/// at 4 (docs/results.md, "Empty space").
inline constexpr double kContradictionWeight = 2.0;

/// One pose the dense search found, refined on the full grid.
struct DensePose {
  Rigid2D transform;   ///< maps source x, y onto target x, y
  int offset = 0;      ///< target slice index - source slice index
  size_t inliers = 0;  ///< source cells that land within inlier_radius_cells of a target cell
  /// Telling cells (off walls, floors and ceilings) of either map that land on
  /// the other: what ranks the poses. Both ways, so that neither map's own
  /// clutter decides alone.
  size_t telling_inliers = 0;
  int support = 0;  ///< source slices with at least half their cells on target cells
  /// Source slices with at least half of their cells that land where the
  /// target saw anything (at any height) on target cells: a crop sharing 30 %
  /// of the other cannot land half of all its cells, however right the pose.
  int support_seen = 0;
  /// Telling cells of either map that land where the other saw empty space:
  /// no cell within inlier_radius_cells, occupancy below and above.
  size_t contradicted = 0;
  /// What ranks the poses: telling inliers, less what the pose contradicts.
  double score() const;
};

class PoseLander;  // pose_lander.hpp

struct DenseSearch {
  /// False when the maps are too large for it (see kMaxCoarsening) or empty.
  bool searched = false;
  std::vector<DensePose> poses;  ///< distinct poses, highest score first
};

/// Whether `stack` is small enough for searchDensely and holds every slice's cells.
bool denseSearchable(const SliceStack& stack, const DenseSearchParams& params = {});

/// Correlates the maps' occupancy on a coarse raster at every yaw step, shift
/// and height offset (FFT per slice pair), then refines the best distinct
/// coarse poses on the full grid (refineOnOccupancy) and counts their inliers.
/// Two poses are the same when `same` accepts them at `pivot` and their
/// offsets are within one coarse cell.
DenseSearch searchDensely(const SliceStack& target, const SliceStack& source, const ConsensusParams& same,
                          const Eigen::Vector2d& pivot, const DenseSearchParams& params = {});
/// searchDensely on the two stacks `land` prepared (made with the same
/// params but for the coarse raster's), its preparation shared with what
/// else lands poses on them.
DenseSearch searchDensely(const PoseLander& land, const ConsensusParams& same, const Eigen::Vector2d& pivot,
                          const DenseSearchParams& params = {});

}  // namespace tomomap
