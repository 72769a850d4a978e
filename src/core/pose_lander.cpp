#include "pose_lander.hpp"

#include <algorithm>
#include <cstring>
#include <map>
#include <mutex>
#include <optional>

#include "pose_judge.hpp"

namespace tomomap {

using dense_detail::Cell;
using dense_detail::cellsOf;
using dense_detail::columnsOf;
using dense_detail::dilatedSlices;
using dense_detail::landings;
using dense_detail::mostInliersAt;
using dense_detail::PoseJudge;
using dense_detail::SliceWindows;

namespace {

/// The height offset within `reach` slices of `middle` at which `T` lands
/// the most source `cells` on the `dilated` target slices of raster `grid`
/// (occupancyHeightOffset).
template <typename Columns>
int mostInliersNear(const Columns& dilated, const std::vector<Cell>& cells, const SliceGrid& grid, const Rigid2D& T,
                    int middle, int reach) {
  return mostInliersAt(dilated, cells, landings(cells, T, grid), middle - reach, 2 * reach + 1, middle);
}

/// A transform told apart by its bits (so that -0.0 and a NaN are transforms of their own).
std::array<uint64_t, 3> transformBits(const Rigid2D& T) {
  const auto bits = [](double x) {
    uint64_t b;
    std::memcpy(&b, &x, sizeof b);
    return b;
  };
  return {bits(T.yaw), bits(T.t.x()), bits(T.t.y())};
}

/// `poses` by transform: the indices of the poses of each distinct one (transformBits).
std::vector<std::vector<size_t>> byTransform(const PoseLander::Poses& poses) {
  std::map<std::array<uint64_t, 3>, size_t> index;
  std::vector<std::vector<size_t>> out;
  for (size_t n = 0; n < poses.size(); ++n) {
    const auto [at, added] = index.try_emplace(transformBits(poses[n].first), out.size());
    if (added) out.emplace_back();
    out[at->second].push_back(n);
  }
  return out;
}

/// Where transform `T` lands `forth_cells` on the target and `back_cells` on the source.
std::shared_ptr<const PoseLander::Memo::Landed> landedBy(const PoseJudge& judge, const Rigid2D& T,
                                                         const std::vector<Cell>& forth_cells,
                                                         const std::vector<Cell>& back_cells) {
  return std::make_shared<const PoseLander::Memo::Landed>(landings(forth_cells, T, judge.target.grid),
                                                          landings(back_cells, T.inverse(), judge.source.grid));
}

/// Calls f(n, landed) for each of `poses` with `land(T)`, where its transform
/// lands the cells (landedBy): landed once per distinct transform (a climb's
/// steps and a ring of shifts land each at several heights, and where a
/// transform lands the cells does not depend on the height), the transforms
/// spread over `threads`. Returns each distinct transform with its landing.
template <typename Land, typename F>
std::vector<std::pair<Rigid2D, std::shared_ptr<const PoseLander::Memo::Landed>>> forEachLanding(
    const PoseLander::Poses& poses, int threads, const Land& land, const F& f) {
  const std::vector<std::vector<size_t>> groups = byTransform(poses);
  std::vector<std::pair<Rigid2D, std::shared_ptr<const PoseLander::Memo::Landed>>> landed(groups.size());
#pragma omp parallel for schedule(dynamic) num_threads(threads)
  for (size_t g = 0; g < groups.size(); ++g) {
    const Rigid2D& T = poses[groups[g].front()].first;
    landed[g] = {T, land(T)};
    for (size_t n : groups[g]) f(n, *landed[g].second);
  }
  return landed;
}

}  // namespace

std::vector<std::vector<SliceLanding>> landSlices(const SliceStack& target, const SliceStack& source,
                                                  const std::vector<std::pair<Rigid2D, int>>& poses,
                                                  const DenseSearchParams& params) {
  return PoseLander(target, source, params).slices(poses);
}

PoseLander::PoseLander(const SliceStack& target, const SliceStack& source, const DenseSearchParams& params)
    : judge_(std::make_shared<const PoseJudge>(target, source, params)),
      refine_(std::make_shared<Refiner>()),
      threads_(std::max(1, params.threads)) {
  // On maps a dense search reaches (the wide one's bound: BitColumns take a
  // word a pixel per 64 slices, at most a few MB there) a pose's height is
  // read down the target's columns; on larger ones, slice by slice.
  DenseSearchParams widest = params;
  widest.coarse_side = std::max(params.coarse_side, kWideCoarseSide);
  if (denseSearchable(target, widest))
    columns_ = std::make_shared<const BitColumns>(columnsOf(judge_->dilated, target.grid));
}

std::vector<DensePose> PoseLander::operator()(const Poses& poses) const {
  std::vector<DensePose> out(poses.size());
  forEachLanding(
      poses, threads_,
      [&](const Rigid2D& T) { return landedBy(*judge_, T, judge_->source_cells, judge_->target_cells); },
      [&](size_t n, const Memo::Landed& landed) {
        DensePose& p = out[n];
        p.transform = poses[n].first, p.offset = poses[n].second;
        PoseJudge::judge(p, judge_->forth(landed.first, p.offset), judge_->backwards(landed.second, p.offset));
      });
  return out;
}

std::vector<double> PoseLander::scores(const Poses& poses, Memo* memo) const {
  Memo own;
  Memo& m = memo ? *memo : own;
  if (m.of_ != judge_.get()) m = Memo{}, m.of_ = judge_.get();
  std::vector<double> out(poses.size());
  // The poses it has not counted, by transform; each transform's landings
  // from the memo where the last call made them.
  Poses pending;
  std::vector<size_t> at;  // each pending pose's index in `poses`
  for (size_t n = 0; n < poses.size(); ++n)
    if (const auto known = m.scored_.find({transformBits(poses[n].first), poses[n].second}); known != m.scored_.end())
      out[n] = known->second;
    else
      pending.push_back(poses[n]), at.push_back(n);
  const auto landed = forEachLanding(
      pending, threads_,
      [&](const Rigid2D& T) {
        const auto made = m.landed_.find(transformBits(T));
        return made != m.landed_.end() ? made->second
                                       : landedBy(*judge_, T, judge_->source_telling, judge_->target_telling);
      },
      [&](size_t k, const Memo::Landed& l) {
        out[at[k]] = judge_->score(pending[k].first, pending[k].second, l.first, l.second);
      });
  if (!memo) return out;
  // Kept: every count, and the landings of this call's transforms alone.
  std::map<Memo::Key, std::shared_ptr<const Memo::Landed>> kept;
  for (const auto& [T, l] : landed) kept.emplace(transformBits(T), l);
  for (const auto& [T, offset] : poses)
    if (const auto made = m.landed_.find(transformBits(T)); made != m.landed_.end())
      kept.emplace(made->first, made->second);
  m.landed_ = std::move(kept);
  for (size_t k = 0; k < pending.size(); ++k)
    m.scored_.emplace(std::pair{transformBits(pending[k].first), pending[k].second}, out[at[k]]);
  return out;
}

std::vector<std::vector<SliceLanding>> PoseLander::slices(const Poses& poses) const {
  std::vector<std::vector<SliceLanding>> out(poses.size());
#pragma omp parallel for schedule(dynamic) num_threads(threads_)
  for (size_t n = 0; n < poses.size(); ++n)
    judge_->forth(landings(judge_->source_cells, poses[n].first, judge_->target.grid), poses[n].second, &out[n]);
  return out;
}

int PoseLander::heightOffset(const Rigid2D& T, int middle, int reach) const {
  if (columns_) return mostInliersNear(*columns_, judge_->source_cells, judge_->target.grid, T, middle, reach);
  return mostInliersNear(SliceWindows{judge_->dilated}, judge_->source_cells, judge_->target.grid, T, middle, reach);
}

bool PoseLander::lands(const SliceStack& target, const SliceStack& source) const {
  return &judge_->target == &target && &judge_->source == &source;
}

struct PoseLander::Refiner {
  std::once_flag made;
  std::optional<OccupancyRefiner> refiner;
};

const OccupancyRefiner& PoseLander::refiner() const {
  std::call_once(refine_->made, [this] { refine_->refiner.emplace(judge_->target, judge_->source); });
  return *refine_->refiner;
}

DensePose landPose(const PoseLander& land, const Rigid2D& T, int offset) { return land({{T, offset}}).front(); }

DensePose landPose(const SliceStack& target, const SliceStack& source, const Rigid2D& T, int offset,
                   const DenseSearchParams& params) {
  return landPose(PoseLander(target, source, params), T, offset);
}

int occupancyHeightOffset(const SliceStack& target, const SliceStack& source, const Rigid2D& T, int middle, int reach,
                          const DenseSearchParams& params) {
  return mostInliersNear(SliceWindows{dilatedSlices(target, params)}, cellsOf(source, params.wall_spread), target.grid,
                         T, middle, reach);
}

}  // namespace tomomap
