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

/// `p` moved one step at a time to the step that lands most, while it lands more.
DensePose climb(const SliceStack& target, const SliceStack& source, DensePose p, const DenseSearchParams& params) {
  const SliceGrid& sg = source.grid;
  const Eigen::Vector2d centre(sg.x_min + 0.5 * sg.width * sg.cell, sg.y_min + 0.5 * sg.height * sg.cell);
  const double yaw_step = 2.0 / std::hypot(sg.width, sg.height);
  for (int step = 0; step < kMaxSteps; ++step) {
    const std::vector<DensePose> landed =
        landPoses(target, source, stepsFrom(p, target.grid.cell, yaw_step, centre), params);
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

}  // namespace tomomap

namespace tomomap {

DensePose uphill(const SliceStack& target, const SliceStack& source, const Rigid2D& T, int offset,
                 const DenseSearchParams& params) {
  DensePose top = climb(target, source, landPose(target, source, T, offset, params), params);
  DenseRefineParams refine;
  refine.threads = params.threads;
  for (int round = 0; round < kMaxRefinements; ++round) {
    const Rigid2D refined = refineOnOccupancy(target, source, top.offset, top.transform, refine).transform;
    const DensePose next = climb(target, source, landPose(target, source, refined, top.offset, params), params);
    if (next.score() <= top.score()) break;
    top = next;
  }
  return top;
}

}  // namespace tomomap
