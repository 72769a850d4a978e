#include "nearby_poses.hpp"

#include <algorithm>

namespace tomomap {

DensePose bestAround(const SliceStack& target, const SliceStack& source, const Rigid2D& T, int offset, int inner_cells,
                     int outer_cells, const DenseSearchParams& params) {
  std::vector<std::pair<Rigid2D, int>> around;
  for (int dy = -outer_cells; dy <= outer_cells; ++dy)
    for (int dx = -outer_cells; dx <= outer_cells; ++dx) {
      const int r2 = dx * dx + dy * dy;
      if (r2 <= inner_cells * inner_cells || r2 > outer_cells * outer_cells) continue;
      Rigid2D shifted = T;
      shifted.t += target.grid.cell * Eigen::Vector2d(dx, dy);
      for (int o = offset - 1; o <= offset + 1; ++o) around.emplace_back(shifted, o);
    }
  const std::vector<DensePose> landed = landPoses(target, source, around, params);
  if (landed.empty()) return DensePose{T, offset, 0};
  return *std::max_element(landed.begin(), landed.end(),
                           [](const DensePose& a, const DensePose& b) { return a.score() < b.score(); });
}

}  // namespace tomomap
