#pragma once
// Tomographic slicing: a map becomes a stack of horizontal binary occupancy images.
#include <algorithm>
#include <cstdint>
#include <opencv2/core.hpp>

#include "types.hpp"

namespace tomomap {

/// The raster every slice of one map shares.
struct SliceGrid {
  double cell = 0;                         ///< pixel size = grid size g [m]
  double x_min = 0, y_min = 0, z_min = 0;  ///< map-frame position of pixel (0,0) and slice 0 [m]
  int width = 0, height = 0;               ///< image size [pixels]

  /// Height of slice k's centre [m].
  double sliceHeight(int k) const { return z_min + k * cell; }
  /// Slice index of height z: slice k holds h_k - g/2 < z <= h_k + g/2.
  int sliceIndex(double z) const { return static_cast<int>(std::ceil((z - z_min) / cell - 0.5)); }
  /// Map-frame x, y [m] of a (sub)pixel position (pixel centres are
  /// integers), in double throughout: a cell's centre taken through float and
  /// back (toMetres) came out of one build rounded and of the next not
  /// (docs/results.md, "Cheaper candidates").
  Eigen::Vector2d pixelCentre(double u, double v) const { return {x_min + (u + 0.5) * cell, y_min + (v + 0.5) * cell}; }
  /// pixelCentre in float: a keypoint's position, as the features carry it.
  Eigen::Vector2f toMetres(float u, float v) const { return pixelCentre(u, v).cast<float>(); }
  /// Centre [m] of the cell stored as `index` (v * width + u) in SliceStack::cells.
  Eigen::Vector2d cellCentre(uint32_t index) const {
    const auto w = static_cast<uint32_t>(width);
    return pixelCentre(static_cast<int>(index % w), static_cast<int>(index / w));
  }
  bool operator==(const SliceGrid& o) const {
    return cell == o.cell && x_min == o.x_min && y_min == o.y_min && z_min == o.z_min && width == o.width &&
           height == o.height;
  }
  /// The inverse: (sub)pixel position of map-frame x, y [m]; centres are integers.
  Eigen::Vector2d toPixel(double x, double y) const { return {(x - x_min) / cell - 0.5, (y - y_min) / cell - 0.5}; }
  /// Map-frame x, y [m] of the raster's centre (what a search turns it about).
  Eigen::Vector2d centre() const { return {x_min + 0.5 * width * cell, y_min + 0.5 * height * cell}; }
};

/// Occupied cells per slice, stored sparsely (pixel index v * width + u, sorted,
/// unique) so that a tall map does not hold every image at once.
struct SliceStack {
  SliceGrid grid;
  std::vector<std::vector<uint32_t>> cells;  ///< per slice; empty = too sparse to describe (kSparsestSlice)
  /// Per slice, whether the map had any point at its height: a slice too
  /// sparse to describe was seen, a slab between two floors was not (the
  /// empty space a pose is judged on reads the difference: enclosure.hpp,
  /// Enclosure). Empty where not known: every slice seen (seenAt).
  std::vector<bool> seen{};
  size_t stray = 0;  ///< points left out as stray returns (map_bounds.hpp)
  /// Some slices' cells are not here: they crossed the network as features.
  bool partial = false;

  int size() const { return static_cast<int>(cells.size()); }
  /// Whether slice k was seen: a slice `seen` does not cover counts as seen.
  bool seenAt(int k) const { return static_cast<size_t>(k) >= seen.size() || seen[static_cast<size_t>(k)]; }
  /// Slices with cells (the others are too sparse to describe).
  int occupiedSlices() const {
    return static_cast<int>(std::count_if(cells.begin(), cells.end(), [](const auto& c) { return !c.empty(); }));
  }
  /// Renders slice k as a CV_8U image, 255 = occupied, with `pad` empty pixels
  /// around it (ORB finds no corners within its border distance).
  cv::Mat image(int k, int pad = 0) const { return image(k, cv::Rect(0, 0, grid.width, grid.height), pad); }
  /// The same for `area` of the raster alone: its pixel (0, 0) is raster pixel
  /// (area.x - pad, area.y - pad).
  cv::Mat image(int k, const cv::Rect& area, int pad) const;
  /// The smallest area of the raster that holds slice k's occupied cells.
  cv::Rect occupiedArea(int k) const;
};

/// Largest image side accepted, so a tiny grid on a large map fails loudly
/// instead of allocating gigabytes.
constexpr int kMaxImageSide = 16384;

/// A slice with fewer occupied cells than this share of its raster's width +
/// height is too sparse to describe and kept empty. The paper asks for width +
/// height points; a thinned LiDAR crop (one point in 3-10) at 0.2 m then kept 1-2
/// of its 12-14 slices, and every one of them was refused for too few
/// descriptive slices. At a quarter, the kitti crops of seeds 1-300 were
/// answered right 31 times where half answered 21 (the paper's method 24),
/// nothing wrong (docs/results.md).
constexpr double kSparsestSlice = 0.25;

/// Slices `points` (already voxel-filtered at `cell`) within their robust
/// bounds (stray returns left out and counted). Slices with fewer occupied
/// cells than `sparsest` times (width + height) are kept empty (too sparse to
/// describe); empty slices at the bottom and top are trimmed. Throws InputError if the
/// raster would exceed kMaxImageSide. Uses `threads` threads (0: every core).
/// With `keep` (an earlier version of the map, sliced at `cell`), its raster
/// and slice heights are kept while the points stay within them: a slice the
/// change did not touch comes out as it was.
SliceStack makeSlices(const Points& points, double cell, int threads = 0, const SliceStack* keep = nullptr,
                      double sparsest = kSparsestSlice);

/// The share of width + height a slice's cells reach in the stacks a dense
/// search answering alone searches (fullSlices); the sparser slices kSparsestSlice
/// keeps check an answer found otherwise. With every slice, the dense searches
/// answered 176 RGB-D crops right and 17 wrong (sunrgbd seeds 1-300, g 0.05
/// and 0.1); with these, 76 and 2.
constexpr double kFullSlice = 0.5;

/// `stack` with its slices of fewer cells than kFullSlice times (width +
/// height) emptied and its empty ends trimmed, as makeSlices would have sliced
/// it at that bar: the raster and each slice's height kept, slice 0 the
/// lowest full slice.
SliceStack fullSlices(const SliceStack& stack);

/// The same occupancy at twice the cell: each 2 x 2 block of cells and each
/// two slices become one (a cell occupied where any of its eight was). Pooled
/// slice k holds slices 2k and 2k + 1, so its centre sits half a fine slice
/// above slice 2k's: an offset of K pooled slices is 2K fine ones.
SliceStack pooled(const SliceStack& fine);

/// A run of neighbouring slices alike in being seen or not (SliceStack::seenAt).
struct SliceRun {
  int first = 0, last = 0;  ///< its lowest and highest slice [slices]
  bool seen = true;
};

/// `stack`'s slices as runs of seen and unseen ones, lowest first.
std::vector<SliceRun> seenRuns(const SliceStack& stack);

}  // namespace tomomap
