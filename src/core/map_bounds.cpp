#include "map_bounds.hpp"

#include <algorithm>
#include <vector>

namespace tomomap {

namespace {

/// Puts the `k` smallest values of `v` in order at its front and the `k`
/// largest in order at its back: all the stray test looks at, in linear time
/// where a whole sort would take n log n.
void sortTails(std::vector<float>& v, size_t k) {
  if (2 * k >= v.size()) {
    std::sort(v.begin(), v.end());
    return;
  }
  const auto low_end = v.begin() + static_cast<long>(k), high_begin = v.end() - static_cast<long>(k);
  std::nth_element(v.begin(), low_end - 1, v.end());
  std::sort(v.begin(), low_end);
  std::nth_element(low_end, high_begin, v.end());
  std::sort(high_begin, v.end());
}

}  // namespace

MapBounds robustBounds(const Points& points) {
  MapBounds b;
  const size_t n = points.size();
  if (n == 0) return b;
  const size_t tail = std::max<size_t>(1, static_cast<size_t>(kStrayShare * static_cast<double>(n)));
  std::vector<float> v(n);
  for (int axis = 0; axis < 3; ++axis) {
    for (size_t i = 0; i < n; ++i) v[i] = points[i][axis];
    sortTails(v, tail + 1);
    size_t first = 0, last = n - 1;
    // The innermost qualifying gap at each end: everything beyond it goes.
    for (size_t i = 1; i <= tail && i < n; ++i)
      if (v[i] - v[i - 1] >= kStrayGap) first = i;
    for (size_t i = 1; i <= tail && i < n; ++i)
      if (v[n - i] - v[n - i - 1] >= kStrayGap) last = n - i - 1;
    if (first > last) {  // nothing but strays (a tiny map): keep it whole
      first = 0;
      last = n - 1;
    }
    b.lo[axis] = v[first];
    b.hi[axis] = v[last];
  }
  b.outside = static_cast<size_t>(
      std::count_if(points.begin(), points.end(), [&](const Eigen::Vector3f& p) { return !b.contains(p); }));
  return b;
}

}  // namespace tomomap
