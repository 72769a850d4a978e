#pragma once
// Where a map saw through empty space: what a pose contradicts when it lands
// a telling cell there (pose_judge.hpp).
#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "slices.hpp"

namespace tomomap {

/// Where a map saw through empty space: a cell of a column between occupancy
/// below and above (floor and ceiling, floor and table), as a room's scan
/// sees its inside; a column open at the bottom or top may be unseen or
/// outside. Two slices of margin each way, for a floor's or ceiling's
/// thickness under noise. The occupancy must lie in the cell's storey, the
/// run of heights the map saw (SliceStack::seen) around it: a height at which
/// it saw nothing (a slab between two floors) was not seen through, so the
/// floor of a storey above does not enclose the room below, and two like
/// floors enclose alike.
class Enclosure {
 public:
  explicit Enclosure(const SliceStack& s);
  /// Whether pixel `idx` of slice `k` lies between occupancy below and above
  /// in its storey. Inline: it is asked for every telling cell a pose lands
  /// off the other map.
  bool encloses(int idx, int k) const {
    const auto p = static_cast<size_t>(idx);
    if (lowest_[p] > k - kMargin || highest_[p] < k + kMargin) return false;  // not even by the whole column
    const auto [bottom, top] = storey_[static_cast<size_t>(k)];
    if (lowest_[p] >= bottom && highest_[p] <= top) return true;  // the whole column lies in k's storey
    const auto begin = slices_.begin() + first_[p], end = slices_.begin() + first_[p + 1];
    const auto above = std::lower_bound(begin, end, k + kMargin);
    if (above == end || *above > top) return false;
    const auto below = std::upper_bound(begin, end, k - kMargin);
    return below != begin && *(below - 1) >= bottom;
  }

 private:
  /// first_ and slices_, for a map with more than one storey: a column that
  /// reaches past a storey is looked up in its slices (a counting sort by pixel).
  void indexColumns(const SliceStack& s);

  static constexpr int kMargin = 2;          ///< [slices]
  std::vector<uint16_t> lowest_, highest_;   ///< per pixel, its column's lowest and highest occupied slice
  std::vector<std::pair<int, int>> storey_;  ///< per slice, its storey's lowest and highest slice
  /// With more than one storey: per pixel, where its column starts in slices_
  /// (and one past the last), and each column's occupied slices, ascending.
  std::vector<uint32_t> first_;
  std::vector<uint16_t> slices_;
};

}  // namespace tomomap
