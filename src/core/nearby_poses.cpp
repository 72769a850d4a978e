#include "nearby_poses.hpp"

#include <algorithm>
#include <cmath>

#include "dense_refine.hpp"

namespace tomomap {
namespace {

/// Upper bounds that only keep a climb finite: each step lands more telling
/// cells, so a climb ends on its own within the poses the maps allow.
constexpr int kMaxSteps = 200, kMaxRefinements = 10;

DensePose best(const std::vector<DensePose>& landed) {
  return *std::max_element(landed.begin(), landed.end(),
                           [](const DensePose& a, const DensePose& b) { return a.score() < b.score(); });
}

/// The poses one step from `p` (uphill's steps).
std::vector<std::pair<Rigid2D, int>> stepsFrom(const DensePose& p, double cell, double yaw_step,
                                               const Eigen::Vector2d& centre) {
  std::vector<std::pair<Rigid2D, int>> steps;
  const Eigen::Vector2d pivot = p.transform.apply(centre);
  for (int o = p.offset - 1; o <= p.offset + 1; ++o) {
    if (o != p.offset) steps.emplace_back(p.transform, o);
    for (int sign : {-1, 1}) {
      Rigid2D T = p.transform;
      T.t.x() += sign * cell;
      steps.emplace_back(T, o);
      T = p.transform;
      T.t.y() += sign * cell;
      steps.emplace_back(T, o);
      T.yaw = p.transform.yaw + sign * yaw_step;
      T.t = pivot - Rigid2D{T.yaw, Eigen::Vector2d::Zero()}.apply(centre);
      steps.emplace_back(T, o);
    }
  }
  return steps;
}

/// `p` moved one step at a time to the step that lands most, while it lands
/// more; `source` is the raster `land` lands the source's cells from.
DensePose climb(const PoseLander& land, const SliceGrid& source, double cell, DensePose p) {
  const double yaw_step = 2.0 / std::hypot(source.width, source.height);
  for (int step = 0; step < kMaxSteps; ++step) {
    const std::vector<DensePose> landed = land(stepsFrom(p, cell, yaw_step, source.centre()));
    if (landed.empty()) break;
    const DensePose next = best(landed);
    if (next.score() <= p.score()) break;
    p = next;
  }
  return p;
}

}  // namespace

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
  return best(landed);
}

DensePose uphill(const SliceStack& target, const SliceStack& source, const Rigid2D& T, int offset,
                 const DenseSearchParams& params) {
  return uphill(poseLander(target, source, params), target, source, T, offset, params);
}

DensePose uphill(const PoseLander& land, const SliceStack& target, const SliceStack& source, const Rigid2D& T,
                 int offset, const DenseSearchParams& params) {
  const double cell = target.grid.cell;
  DensePose top = climb(land, source.grid, cell, landPose(land, T, offset));
  DenseRefineParams refine;
  refine.threads = params.threads;
  for (int round = 0; round < kMaxRefinements; ++round) {
    const Rigid2D refined = refineOnOccupancy(target, source, top.offset, top.transform, refine).transform;
    const DensePose next = climb(land, source.grid, cell, landPose(land, refined, top.offset));
    if (next.score() <= top.score()) break;
    top = next;
  }
  return top;
}

}  // namespace tomomap
