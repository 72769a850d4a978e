#include "dense_search.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "bit_raster.hpp"
#include "dense_refine.hpp"
#include "match_params.hpp"
#include "pose_judge.hpp"
#include "pose_lander.hpp"
#include "spectrum_correlation.hpp"

namespace tomomap {

double DensePose::score() const {
  return static_cast<double>(telling_inliers) - kContradictionWeight * static_cast<double>(contradicted);
}

namespace {

/// The coarse raster's cell in grid cells: `s`'s longest side over `side`.
int coarsening(const SliceStack& s, int side) {
  const int longest = std::max({s.grid.width, s.grid.height, s.size()});
  return std::max(1, (longest + side - 1) / side);
}

/// A correlation's peak: its largest whole count of coincident cells, and
/// the first shift, in the raster's order, at that count. A shift's value
/// is that count times `scale`, up to the transforms' rounding
/// (thousandths): on sparse crops many shifts tie at the largest count, and
/// which one a search keeps is then not a matter of how the transforms
/// round. The largest value is a reduction the compiler vectorises
/// (std::max_element steps one value at a time).
std::pair<double, size_t> peakOf(const RealImage& corr, double scale) {
  float largest = -std::numeric_limits<float>::infinity();
#pragma omp simd reduction(max : largest)
  for (size_t i = 0; i < corr.size(); ++i) largest = corr[i] > largest ? corr[i] : largest;
  const double most = std::round(scale * largest);
  const auto least = static_cast<float>((most - 0.5) / scale);
  const auto top = std::find_if(corr.begin(), corr.end(), [least](float v) { return v >= least; });
  return {most, static_cast<size_t>(top - corr.begin())};
}

/// The best shift at one (yaw, coarse height offset).
struct Peak {
  double score = 0;
  int yaw_step = 0, dz = 0, dx = 0, dy = 0;
};

}  // namespace

using dense_detail::Cell;
using dense_detail::columnsOf;
using dense_detail::landings;
using dense_detail::mostInliersAt;
using dense_detail::PoseJudge;

DenseSearchParams denseSearchParams(const MatchParams& params, DenseSearchParams dp) {
  dp.threads = matchThreads(params);
  return dp;
}

bool denseSearchable(const SliceStack& stack, const DenseSearchParams& params) {
  return stack.size() > 0 && !stack.partial && coarsening(stack, params.coarse_side) <= kMaxCoarsening;
}

DenseSearch searchDensely(const SliceStack& target, const SliceStack& source, const ConsensusParams& same,
                          const Eigen::Vector2d& pivot, const DenseSearchParams& params) {
  if (!denseSearchable(target, params) || !denseSearchable(source, params)) return {};
  return searchDensely(PoseLander(target, source, params), same, pivot, params);
}

DenseSearch searchDensely(const PoseLander& land, const ConsensusParams& same, const Eigen::Vector2d& pivot,
                          const DenseSearchParams& params) {
  DenseSearch out;
  const PoseJudge& judge = *land.judge_;
  const SliceStack &target = judge.target, &source = judge.source;
  if (!denseSearchable(target, params) || !denseSearchable(source, params)) return out;
  const std::vector<Cell>& source_cells = judge.source_cells;
  if (source_cells.empty()) return out;
  out.searched = true;

  const SliceGrid& tg = target.grid;
  const SliceGrid& sg = source.grid;
  const int c =
      std::max({coarsening(target, params.coarse_side), coarsening(source, params.coarse_side), params.min_coarsening});
  const double C = c * tg.cell;  // coarse cell [m]

  // Target: coarse binary images, one per c slices.
  const int xt = (tg.width + c - 1) / c, yt = (tg.height + c - 1) / c, zt = (target.size() + c - 1) / c;
  // Source: turned about its raster's centre, so its coarse raster is a square
  // that holds it at any yaw.
  const Eigen::Vector2d centre = sg.centre();
  const double radius = 0.5 * sg.cell * std::hypot(sg.width, sg.height) + sg.cell;
  const int xs = static_cast<int>(std::ceil(2.0 * radius / C)) + 1, zs = (source.size() + c - 1) / c;
  // Zero-padded so that no shift wraps around.
  const RealFft fft(RealFft::fastSize(yt + xs - 1), RealFft::fastSize(xt + xs - 1));
  const auto pixel = [&fft](int u, int v) {
    return static_cast<size_t>(v) * static_cast<size_t>(fft.cols()) + static_cast<size_t>(u);
  };

  std::vector<Spectrum> tspec(static_cast<size_t>(zt));
  std::vector<int> target_occupied(tspec.size());  // coarse cells per slice: what bounds each offset's peak
  {
    std::vector<RealImage> timg(tspec.size(), RealImage(fft.imageSize(), 0.f));
    const auto tw = static_cast<uint32_t>(tg.width);
    for (int k = 0; k < target.size(); ++k)
      for (uint32_t idx : target.cells[static_cast<size_t>(k)]) {
        float& at =
            timg[static_cast<size_t>(k / c)][pixel(static_cast<int>(idx % tw) / c, static_cast<int>(idx / tw) / c)];
        target_occupied[static_cast<size_t>(k / c)] += at == 0.f;
        at = 1.f;
      }
    for (size_t k = 0; k < timg.size(); ++k)
      if (target_occupied[k] > 0) fft.forward(timg[k], tspec[k]);
  }

  // The source's cells as the coarse raster sees them: one per pixel per
  // coarse slice (a wall's pixel is occupied in most of a coarse slice's c
  // slices, and lands on the same coarse pixel from each), each about the
  // raster's centre. Every yaw step turns all of them.
  std::vector<std::pair<Eigen::Vector2d, int>> coarse_cells;  // (cell - centre, coarse slice)
  {
    std::vector<int> last(static_cast<size_t>(sg.width) * static_cast<size_t>(sg.height), -1);
    for (int k = 0; k < source.size(); ++k)
      for (uint32_t idx : source.cells[static_cast<size_t>(k)])
        if (int& seen = last[idx]; seen != k / c)
          seen = k / c, coarse_cells.emplace_back(sg.cellCentre(idx) - centre, k / c);
  }
  const int steps = std::max(1, static_cast<int>(std::lround(2.0 * kPi / params.yaw_step)));
  const size_t offsets = static_cast<size_t>(zs + zt - 1);
  // Each (yaw step, height offset)'s peak, once correlated.
  std::vector<std::vector<std::optional<Peak>>> peaks(static_cast<size_t>(steps),
                                                      std::vector<std::optional<Peak>>(offsets));
  // Correlates the offsets of `todo`'s steps that may peak in [from, below).
  const auto correlate = [&](const std::vector<int>& todo, double from, double below) {
#pragma omp parallel num_threads(std::max(1, params.threads))
    {
      // Each thread's images and spectra, reused from yaw step to yaw step.
      std::vector<RealImage> simg(static_cast<size_t>(zs), RealImage(fft.imageSize(), 0.f));
      std::vector<Spectrum> sspec(simg.size()), sums;  // sums: per height offset
      RealImage corr;
      std::vector<char> summed;
      std::vector<int> source_occupied(simg.size());
      std::vector<size_t> set;  // the pixels set, to be cleared again
#pragma omp for schedule(dynamic)
      for (size_t n = 0; n < todo.size(); ++n) {
        const int step = todo[n];
        const double yaw = 2.0 * kPi * step / steps, cs = std::cos(yaw), sn = std::sin(yaw);
        std::fill(source_occupied.begin(), source_occupied.end(), 0);
        for (const auto& [d, z] : coarse_cells) {
          const int u = static_cast<int>((cs * d.x() - sn * d.y() + radius) / C);
          const int v = static_cast<int>((sn * d.x() + cs * d.y() + radius) / C);
          float& at = simg[static_cast<size_t>(z)][pixel(u, v)];
          if (at != 0.f) continue;
          at = 1.f;
          ++source_occupied[static_cast<size_t>(z)];
          set.push_back(static_cast<size_t>(z) * fft.imageSize() + pixel(u, v));
        }
        const std::vector<char> wanted = offsetsPeakingWithin(target_occupied, source_occupied, from, below);
        if (std::any_of(wanted.begin(), wanted.end(), [](char w) { return w; })) {
          for (size_t k = 0; k < simg.size(); ++k)
            if (source_occupied[k] > 0)
              fft.forward(simg[k], sspec[k]);
            else
              sspec[k].clear();
          correlateStacks(tspec, sspec, fft.cols() / 2 + 1, sums, summed, wanted);
          // The transforms leave the scale: a pixel's value is the coincident cells times this.
          const double scale = 1.0 / static_cast<double>(fft.imageSize());
          for (int dz = -(zs - 1); dz <= zt - 1; ++dz) {
            const size_t at = static_cast<size_t>(dz + zs - 1);
            if (!summed[at]) continue;
            fft.inverse(sums[at], corr);
            const auto [most, top] = peakOf(corr, scale);
            const int x = static_cast<int>(top % static_cast<size_t>(fft.cols())),
                      y = static_cast<int>(top / static_cast<size_t>(fft.cols()));
            const int dx = x < xt ? x : x - fft.cols(), dy = y < yt ? y : y - fft.rows();
            peaks[static_cast<size_t>(step)][at] = Peak{most, step, dz, dx, dy};
          }
        }
        for (size_t i : set) simg[i / fft.imageSize()][i % fft.imageSize()] = 0.f;
        set.clear();
      }
    }
  };

  // Coarse peaks to poses: a source point p lands in coarse cell
  // floor((R(yaw)(p - centre) + radius) / C) + (dx, dy) of the target.
  const auto poseOf = [&](const Peak& k) {
    const double yaw = 2.0 * kPi * k.yaw_step / steps;
    Rigid2D T{yaw, Eigen::Vector2d::Zero()};
    T.t = Eigen::Vector2d(tg.x_min + radius + k.dx * C, tg.y_min + radius + k.dy * C) - T.apply(centre);
    return DensePose{T, k.dz * c, 0};
  };
  const auto isSame = [&](const DensePose& a, const DensePose& b) {
    return std::abs(a.offset - b.offset) <= c && agree(a.transform, b.transform, same, pivot);
  };
  // The best distinct poses of the peaks correlated so far, and the last one's score.
  const auto distinct = [&](std::vector<DensePose>& coarse) {
    std::vector<Peak> all;
    for (const auto& step : peaks)
      for (const auto& p : step)
        if (p) all.push_back(*p);
    std::stable_sort(all.begin(), all.end(), [](const Peak& a, const Peak& b) { return a.score > b.score; });
    coarse.clear();
    double last = -std::numeric_limits<double>::infinity();
    for (const Peak& k : all) {
      if (static_cast<int>(coarse.size()) >= params.candidates) break;
      const DensePose p = poseOf(k);
      if (std::none_of(coarse.begin(), coarse.end(), [&](const DensePose& q) { return isSame(p, q); }))
        coarse.push_back(p), last = k.score;
    }
    return static_cast<int>(coarse.size()) >= params.candidates ? last : -std::numeric_limits<double>::infinity();
  };
  // Every kSampled-th yaw step is correlated first, at every height offset;
  // the last of the distinct poses their peaks give scores a bar. The other
  // steps then correlate only the offsets whose bound reaches the bar. If
  // the distinct poses of all the peaks still end at or above it, every peak
  // that could be among them was correlated, and they are the poses a search
  // of every offset chooses; otherwise the offsets left out are correlated too.
  constexpr int kSampled = 4;
  std::vector<int> sampled, others;
  for (int step = 0; step < steps; ++step) (step % kSampled == 0 ? sampled : others).push_back(step);
  constexpr double kAny = std::numeric_limits<double>::infinity();
  correlate(sampled, -kAny, kAny);
  std::vector<DensePose> coarse;
  const double bar = distinct(coarse);
  correlate(others, bar, kAny);
  if (distinct(coarse) < bar) {
    correlate(others, -kAny, bar);
    distinct(coarse);
  }

  // Full grid: the best fine offset within the coarse one, then ICP on occupancy.
  std::vector<DensePose> refined(coarse.size());
  // The lander's columns where it made them (every map the wide search reaches).
  std::optional<BitColumns> own;
  if (!land.columns_) own.emplace(columnsOf(judge.dilated, tg));
  const BitColumns& columns = land.columns_ ? *land.columns_ : *own;
  const OccupancyRefiner& refine = land.refiner();
  DenseRefineParams refine_params;
  refine_params.max_cells = params.refine_cells;
  refine_params.threads = 1;  // the loop over the poses has them
#pragma omp parallel for schedule(dynamic) num_threads(std::max(1, params.threads))
  for (size_t n = 0; n < coarse.size(); ++n) {
    DensePose p = coarse[n];
    std::vector<int> landing;
    const auto bestOffsetNear = [&](int middle, int reach) {
      landing = landings(source_cells, p.transform, tg);
      p.offset = mostInliersAt(columns, source_cells, landing, middle - reach, 2 * reach + 1);
    };
    bestOffsetNear(p.offset, c - 1);
    p.transform = refine(p.offset, p.transform, refine_params).transform;
    bestOffsetNear(p.offset, 1);
    judge.judge(p, judge.forth(landing, p.offset));
    refined[n] = p;
  }
  std::stable_sort(refined.begin(), refined.end(),
                   [](const DensePose& a, const DensePose& b) { return a.score() > b.score(); });
  for (const DensePose& p : refined)
    if (std::none_of(out.poses.begin(), out.poses.end(), [&](const DensePose& q) { return isSame(p, q); }))
      out.poses.push_back(p);
  return out;
}

}  // namespace tomomap
