#pragma once
// What a landed pose (dense_search.hpp) tells: whether it is consistent with
// the space the other map saw empty, whether it holds, and whether one score
// leads another beyond chance. Shared by the dense opinion and the check of
// the features' rival answers.
#include <algorithm>
#include <cmath>

#include "dense_search.hpp"

namespace tomomap {

/// A pose that lands more than this share as many telling cells in space the
/// other map saw empty as on its occupancy does not answer or confirm: the
/// right best poses of room pairs (seeds 1-100, low and high noise, at 0.1 m
/// cells) landed at most 0.18, the wrong one a held-out pair answered (seed
/// 208, high noise, g 0.1: 2.75 m off, the right pose not among the search's
/// candidates) 0.24 (docs/results.md, "Empty space").
constexpr double kMostContradicted = 0.2;

/// A lead counts only this many standard deviations beyond chance: a pose's
/// score is a count of cells, and two counts differ by their square roots'
/// sum by chance alone. On a real RGB-D room (sunrgbd-room-2 at g 0.1) the
/// pooled search's best pose led 13 to 7 (1.3 sigma) and was 13.9 m off; right
/// answers on rooms lead by tens of sigma.
constexpr double kSignificant = 3.0;

/// A pose's telling cells in the other map's empty space, per one landed on
/// its occupancy.
inline double contradiction(const DensePose& p) {
  return static_cast<double>(p.contradicted) / static_cast<double>(std::max<size_t>(p.telling_inliers, 1));
}

/// Whether a pose contradicts no more than kMostContradicted.
inline bool consistent(const DensePose& p) { return contradiction(p) <= kMostContradicted; }

/// Whether a pose is consistent over at least `min_support` slices.
inline bool holdsOver(const DensePose& p, int min_support) { return consistent(p) && p.support >= min_support; }

/// Score `a` over score `b` in standard deviations of a difference of two
/// counts (a negative score counts as none).
inline double significance(double a, double b) {
  a = std::max(a, 0.0), b = std::max(b, 0.0);
  return (a - b) / std::sqrt(std::max(a + b, 1.0));
}

}  // namespace tomomap
