#pragma once
// Where a map really is. One stray return 100 m from a room-sized map used to
// stretch the raster twenty-fold, raise the sparse-slice threshold with it and
// leave no slice to match; the slices now span the map without such strays.
#include "types.hpp"

namespace tomomap {

/// A stray tail is at most this share of the points at either end of an axis...
constexpr double kStrayShare = 0.001;
/// ... and this far [m] from the rest along that axis.
constexpr double kStrayGap = 5.0;

struct MapBounds {
  Eigen::Vector3f lo = Eigen::Vector3f::Zero(), hi = Eigen::Vector3f::Zero();
  size_t outside = 0;  ///< points left out (strays)

  bool contains(const Eigen::Vector3f& p) const {
    return (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all();
  }
};

/// The box of `points` (not empty) without stray tails: per axis, the points
/// beyond the widest gap of at least kStrayGap within the outer kStrayShare of
/// them (at least one point) at either end are left out.
MapBounds robustBounds(const Points& points);

}  // namespace tomomap
