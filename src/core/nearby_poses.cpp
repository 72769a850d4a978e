#include "nearby_poses.hpp"

#include <algorithm>
#include <cmath>

namespace tomomap {
namespace {

/// Upper bounds that only keep a climb finite: each step lands more telling
/// cells, so a climb ends on its own within the poses the maps allow.
constexpr int kMaxSteps = 200, kMaxRefinements = 10;

/// The index of the first of the highest scores.
size_t best(const std::vector<double>& scores) {
  return static_cast<size_t>(std::max_element(scores.begin(), scores.end()) - scores.begin());
}

/// The poses one step from (from, offset): uphill's steps.
PoseLander::Poses stepsFrom(const Rigid2D& from, int offset, double cell, double yaw_step,
                            const Eigen::Vector2d& centre) {
  PoseLander::Poses steps;
  const Eigen::Vector2d pivot = from.apply(centre);
  for (int o = offset - 1; o <= offset + 1; ++o) {
    if (o != offset) steps.emplace_back(from, o);
    for (int sign : {-1, 1}) {
      Rigid2D T = from;
      T.t.x() += sign * cell;
      steps.emplace_back(T, o);
      T = from;
      T.t.y() += sign * cell;
      steps.emplace_back(T, o);
      T.yaw = from.yaw + sign * yaw_step;
      T.t = pivot - Rigid2D{T.yaw, Eigen::Vector2d::Zero()}.apply(centre);
      steps.emplace_back(T, o);
    }
  }
  return steps;
}

/// `p` moved one step at a time to the step that lands most, while it lands
/// more; `source` is the raster `land` lands the source's cells from. The
/// steps are scored alone and only where the climb stops is it landed.
DensePose climb(const PoseLander& land, const SliceGrid& source, double cell, const DensePose& from) {
  const double yaw_step = 2.0 / std::hypot(source.width, source.height);
  Rigid2D T = from.transform;
  int offset = from.offset;
  double score = from.score();
  bool moved = false;
  PoseLander::Memo memo;  // a step in height scores the same transforms again
  for (int step = 0; step < kMaxSteps; ++step) {
    const PoseLander::Poses steps = stepsFrom(T, offset, cell, yaw_step, source.centre());
    const std::vector<double> scores = land.scores(steps, &memo);
    const size_t next = best(scores);
    if (scores[next] <= score) break;
    T = steps[next].first, offset = steps[next].second, score = scores[next], moved = true;
  }
  return moved ? landPose(land, T, offset) : from;
}

}  // namespace

DensePose uphill(const SliceStack& target, const SliceStack& source, const Rigid2D& T, int offset,
                 const DenseSearchParams& params) {
  return uphill(PoseLander(target, source, params), T, offset, params.threads);
}

DensePose uphill(const PoseLander& land, const Rigid2D& T, int offset, int threads) {
  const OccupancyRefiner& refine = land.refiner();
  const SliceGrid& source = refine.source().grid;
  const double cell = refine.target().grid.cell;
  DensePose top = climb(land, source, cell, landPose(land, T, offset));
  DenseRefineParams refine_params;
  refine_params.threads = threads;
  for (int round = 0; round < kMaxRefinements; ++round) {
    const Rigid2D refined = refine(top.offset, top.transform, refine_params).transform;
    const DensePose next = climb(land, source, cell, landPose(land, refined, top.offset));
    if (next.score() <= top.score()) break;
    top = next;
  }
  return top;
}

}  // namespace tomomap
