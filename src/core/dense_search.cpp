#include "dense_search.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <future>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <tuple>
#include <utility>

#include "bit_raster.hpp"
#include "dense_refine.hpp"
#include "spectrum_correlation.hpp"

namespace tomomap {

double DensePose::score() const {
  return static_cast<double>(telling_inliers) - kContradictionWeight * static_cast<double>(contradicted);
}

// Named, not anonymous: PoseLander (dense_search.hpp) holds a PoseJudge, and a
// type a header names may not hold members of an anonymous namespace's types.
namespace dense_detail {

int coarsening(const SliceStack& s, int side) {
  const int longest = std::max({s.grid.width, s.grid.height, s.size()});
  return std::max(1, (longest + side - 1) / side);
}

/// An occupied cell's centre [m], its slice, and whether it tells places apart.
struct Cell {
  Eigen::Vector2d p;
  int slice;
  bool telling;
};

/// A room's walls, floor and ceiling fit it turned by a half or a quarter turn
/// as well as the right way; what tells the turns apart is everything else.
/// So a cell is "telling" unless its column (with its neighbours within
/// `wall_spread`) is occupied in most slices (a wall) or its slice is mostly
/// occupied (a floor or a ceiling).
std::vector<Cell> cellsOf(const SliceStack& s, double wall_spread) {
  const int reach = static_cast<int>(std::floor(wall_spread / s.grid.cell + 1e-6));
  const int w = s.grid.width, h = s.grid.height;
  // Per pixel: in how many slices a cell lies within `reach` (a square), and
  // the last slice that counted it, so that a slice counts a pixel once
  // (slices are fewer than kMaxImageSide, so both fit 16 bits).
  constexpr uint16_t kNone = UINT16_MAX;
  std::vector<uint16_t> column(static_cast<size_t>(w) * static_cast<size_t>(h), 0), counted(column.size(), kNone);
  int occupied_slices = 0;
  size_t largest = 0, count = 0;
  for (int k = 0; k < s.size(); ++k) {
    const auto& cells = s.cells[static_cast<size_t>(k)];
    if (cells.empty()) continue;
    ++occupied_slices;
    count += cells.size();
    largest = std::max(largest, cells.size());
    for (uint32_t idx : cells) {
      const int u = static_cast<int>(idx % static_cast<uint32_t>(w)),
                v = static_cast<int>(idx / static_cast<uint32_t>(w));
      for (int y = std::max(0, v - reach); y <= std::min(h - 1, v + reach); ++y)
        for (int x = std::max(0, u - reach); x <= std::min(w - 1, u + reach); ++x) {
          const size_t p = static_cast<size_t>(y) * static_cast<size_t>(w) + static_cast<size_t>(x);
          if (counted[p] != k) counted[p] = static_cast<uint16_t>(k), ++column[p];
        }
    }
  }
  std::vector<Cell> out;
  out.reserve(count);
  for (int k = 0; k < s.size(); ++k) {
    const auto& cells = s.cells[static_cast<size_t>(k)];
    const bool flat = cells.size() * 2 > largest;
    for (uint32_t idx : cells) out.push_back({s.grid.cellCentre(idx), k, !flat && column[idx] * 2 < occupied_slices});
  }
  return out;
}

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
  explicit Enclosure(const SliceStack& s)
      : lowest_(static_cast<size_t>(s.grid.width) * static_cast<size_t>(s.grid.height), UINT16_MAX),
        highest_(lowest_.size(), 0),
        storey_(storeysOf(s)) {
    // A stack has at most kMaxImageSide slices (makeSlices; transport's
    // validate for a peer's): they fit 16 bits.
    for (int k = 0; k < s.size(); ++k)
      for (uint32_t idx : s.cells[static_cast<size_t>(k)]) {
        lowest_[idx] = std::min(lowest_[idx], static_cast<uint16_t>(k));
        highest_[idx] = static_cast<uint16_t>(k);
      }
    // Only a column of a map of more than one storey may reach past its own.
    if (!storey_.empty() && storey_.front().second + 1 < s.size()) indexColumns(s);
  }
  /// Whether pixel `idx` of slice `k` lies between occupancy below and above in its storey.
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
  /// Per slice, the lowest and highest slice of its storey: the run of seen
  /// slices around it (an unseen slice is a storey of its own, enclosing nothing).
  static std::vector<std::pair<int, int>> storeysOf(const SliceStack& s) {
    std::vector<std::pair<int, int>> out(static_cast<size_t>(s.size()));
    for (const SliceRun& run : seenRuns(s))
      for (int k = run.first; k <= run.last; ++k)
        out[static_cast<size_t>(k)] = run.seen ? std::pair{run.first, run.last} : std::pair{k, k};
    return out;
  }
  /// first_ and slices_, for a map with more than one storey: a column that
  /// reaches past a storey is looked up in its slices (a counting sort by pixel).
  void indexColumns(const SliceStack& s) {
    first_.assign(lowest_.size() + 1, 0);
    for (const auto& cells : s.cells)
      for (uint32_t idx : cells) ++first_[idx + 1];
    for (size_t p = 1; p < first_.size(); ++p) first_[p] += first_[p - 1];
    slices_.resize(first_.back());
    std::vector<uint32_t> next(first_.begin(), first_.end() - 1);
    for (int k = 0; k < s.size(); ++k)
      for (uint32_t idx : s.cells[static_cast<size_t>(k)]) slices_[next[idx]++] = static_cast<uint16_t>(k);
  }

  static constexpr int kMargin = 2;          ///< [slices]
  std::vector<uint16_t> lowest_, highest_;   ///< per pixel, its column's lowest and highest occupied slice
  std::vector<std::pair<int, int>> storey_;  ///< per slice, its storey's lowest and highest slice
  /// With more than one storey: per pixel, where its column starts in slices_
  /// (and one past the last), and each column's occupied slices, ascending.
  std::vector<uint32_t> first_;
  std::vector<uint16_t> slices_;
};

/// The best shift at one (yaw, coarse height offset).
struct Peak {
  double score = 0;
  int yaw_step = 0, dz = 0, dx = 0, dy = 0;
};

/// Where `T` puts each of `cells` on the raster `grid`: its pixel's index, or
/// -1 off the raster. The same at every height offset, so found once per pose.
std::vector<int> landings(const std::vector<Cell>& cells, const Rigid2D& T, const SliceGrid& grid) {
  std::vector<int> out;
  out.reserve(cells.size());
  const Rigid2D::Applier move = T.applier();
  for (const Cell& c : cells) {
    const Eigen::Vector2d q = move(c.p);
    const Eigen::Vector2d f = grid.toPixel(q.x(), q.y());
    // Rounded half away from zero as std::lround rounds, without its call (as
    // long as the rest of the landing, `perf` on the slowest matrix pair): at
    // or below -0.5 pixels a position is off the raster whatever it rounds
    // to, and above it truncating f + 0.5 rounds alike (but for the one
    // double just below each half, which the sum rounds up).
    const double fu = f.x() + 0.5, fv = f.y() + 0.5;
    if (!(fu > 0 && fv > 0)) {
      out.push_back(-1);
      continue;
    }
    const int u = static_cast<int>(fu), v = static_cast<int>(fv);
    out.push_back(u >= grid.width || v >= grid.height ? -1 : v * grid.width + u);
  }
  return out;
}

/// How many of the source `cells`, landed at `landing`, fall on a dilated
/// target cell at height `offset`.
struct Tally {
  size_t inliers = 0, telling = 0;
  int slices = 0;  ///< source slices with at least half their cells on the target
  /// The same, of the cells that land where the target saw anything at any height (`seen`).
  int slices_seen = 0;
  size_t contradicted = 0;  ///< telling cells off the target, in space it encloses (if given)
};

Tally countInliers(const std::vector<BitRaster>& dilated, const std::vector<Cell>& cells,
                   const std::vector<int>& landing, int offset, int source_slices, const Enclosure* enclosure = nullptr,
                   const BitRaster* seen = nullptr, std::vector<SliceLanding>* per_slice = nullptr) {
  Tally t;
  std::vector<size_t> on(static_cast<size_t>(source_slices), 0), all(on), all_seen(on);
  if (per_slice) {
    per_slice->assign(static_cast<size_t>(source_slices), SliceLanding{});
    for (int k = 0; k < source_slices; ++k) (*per_slice)[static_cast<size_t>(k)].slice = k;
  }
  // Each source slice's target image at `offset` (null where there is none),
  // looked up once per call rather than once per cell.
  std::vector<const BitRaster*> image(static_cast<size_t>(source_slices), nullptr);
  for (int k = 0; k < source_slices; ++k)
    if (const int i = k + offset;
        i >= 0 && i < static_cast<int>(dilated.size()) && !dilated[static_cast<size_t>(i)].empty())
      image[static_cast<size_t>(k)] = &dilated[static_cast<size_t>(i)];
  const BitRaster* seen_pixels = seen && !seen->empty() ? seen : nullptr;
  for (size_t n = 0; n < cells.size(); ++n) {
    const Cell& c = cells[n];
    SliceLanding* s = per_slice ? &(*per_slice)[static_cast<size_t>(c.slice)] : nullptr;
    if (s) ++s->cells, s->telling += c.telling;
    const BitRaster* target = image[static_cast<size_t>(c.slice)];
    if (!target) continue;
    ++all[static_cast<size_t>(c.slice)];
    if (landing[n] < 0) continue;
    const auto at = static_cast<size_t>(landing[n]);
    if (seen_pixels && seen_pixels->test(at)) {
      ++all_seen[static_cast<size_t>(c.slice)];
      if (s) ++s->seen;
    }
    if (!target->test(at)) {
      const bool against = c.telling && enclosure && enclosure->encloses(landing[n], c.slice + offset);
      t.contradicted += against;
      if (s) s->contradicted += against;
      continue;
    }
    ++t.inliers;
    t.telling += c.telling;
    ++on[static_cast<size_t>(c.slice)];
    if (s) ++s->on, s->telling_on += c.telling;
  }
  for (size_t k = 0; k < on.size(); ++k) {
    t.slices += all[k] > 0 && 2 * on[k] >= all[k];
    t.slices_seen += all_seen[k] > 0 && 2 * on[k] >= all_seen[k];
  }
  return t;
}

/// Per nibble, its four bits spread to the four 16-bit lanes of a word: a
/// column's window of offsets, a nibble at a time, adds one to each lane
/// whose offset it holds.
constexpr std::array<uint64_t, 16> kNibbleLanes = [] {
  std::array<uint64_t, 16> out{};
  for (size_t m = 0; m < 16; ++m)
    for (size_t j = 0; j < 4; ++j)
      if ((m >> j) & 1U) out[m] |= uint64_t{1} << (16 * j);
  return out;
}();

/// A stack of dilated slices as mostInliersAt reads it, a window of slices
/// down a pixel's column, each slice tested in turn (BitColumns::window).
struct SliceWindows {
  const std::vector<BitRaster>& slices;
  int size() const { return static_cast<int>(slices.size()); }
  uint64_t window(size_t idx, int first, int count) const {
    uint64_t out = 0;
    for (int k = 0; k < count; ++k)
      if (const BitRaster& s = slices[static_cast<size_t>(first + k)]; !s.empty() && s.test(idx))
        out |= uint64_t{1} << k;
    return out;
  }
};

/// The height offset from `lowest` to `lowest + count - 1` (1 <= count <=
/// 64) at which most of the source `cells`, landed at `landing`, fall on a
/// dilated target cell (`dilated`: SliceWindows or BitColumns of the
/// target's dilated slices; countInliers' inliers; the first of the most,
/// or `preferred`, an offset in that range, where it is among them),
/// counted for every offset in one pass over the cells: choosing a height
/// needs the inliers alone, not the rest of a tally.
///
/// A cell's offsets are one window down its column, counted four offsets
/// to a word (kNibbleLanes). On maps a dense search reaches the windows are
/// read off BitColumns: on the slowest matrix pair that took half the time
/// of testing each offset's slice in turn.
template <typename Columns>
int mostInliersAt(const Columns& dilated, const std::vector<Cell>& cells, const std::vector<int>& landing, int lowest,
                  int count, std::optional<int> preferred = {}) {
  if (count < 1 || count > 64) throw std::logic_error("mostInliersAt: 1 to 64 offsets at a time");
  std::vector<size_t> inliers(static_cast<size_t>(count), 0);
  std::vector<uint64_t> lanes(static_cast<size_t>(count + 3) / 4, 0);
  size_t pending = 0;  // cells counted into the lanes since they were emptied: below 2^16
  const auto flush = [&] {
    for (size_t k = 0; k < inliers.size(); ++k) inliers[k] += (lanes[k / 4] >> (16 * (k % 4))) & 0xFFFF;
    std::fill(lanes.begin(), lanes.end(), 0);
    pending = 0;
  };
  for (size_t n = 0; n < cells.size(); ++n) {
    if (landing[n] < 0) continue;
    const int base = cells[n].slice + lowest;  // the target slice of offset `lowest`
    const int first = std::max(0, base), last = std::min(dilated.size() - 1, base + count - 1);
    if (first > last) continue;
    uint64_t window = dilated.window(static_cast<size_t>(landing[n]), first, last - first + 1) << (first - base);
    for (size_t q = 0; window != 0; ++q, window >>= 4) lanes[q] += kNibbleLanes[window & 15];
    if (++pending == 0xFFFF) flush();
  }
  flush();
  size_t best = preferred ? static_cast<size_t>(*preferred - lowest) : 0;
  for (size_t k = 0; k < inliers.size(); ++k)
    if (inliers[k] > inliers[best]) best = k;
  return lowest + static_cast<int>(best);
}

/// The height offset within `reach` slices of `middle` at which `T` lands
/// the most source `cells` on the `dilated` target slices of raster `grid`
/// (occupancyHeightOffset).
template <typename Columns>
int mostInliersNear(const Columns& dilated, const std::vector<Cell>& cells, const SliceGrid& grid, const Rigid2D& T,
                    int middle, int reach) {
  return mostInliersAt(dilated, cells, landings(cells, T, grid), middle - reach, 2 * reach + 1, middle);
}

/// `dilated`, the dilated slices of a stack on raster `grid`, by column.
BitColumns columnsOf(const std::vector<BitRaster>& dilated, const SliceGrid& grid) {
  return BitColumns(dilated, static_cast<size_t>(grid.width) * static_cast<size_t>(grid.height));
}

/// Every slice's occupancy grown by inlier_radius_cells (BitRaster::disk): a
/// cell lands on the stack where its pixel is set.
std::vector<BitRaster> dilatedSlices(const SliceStack& stack, const DenseSearchParams& params) {
  const BitRaster::Stamp disk = BitRaster::disk(params.inlier_radius_cells);
  std::vector<BitRaster> out;
  out.reserve(static_cast<size_t>(stack.size()));
  for (const std::vector<uint32_t>& cells : stack.cells) out.emplace_back(stack.grid, cells, disk);
  return out;
}

/// Where a map saw anything at any height: the union of its dilated slices.
BitRaster footprint(const std::vector<BitRaster>& dilated) {
  BitRaster out;
  for (const BitRaster& slice : dilated) out.add(slice);
  return out;
}

std::vector<Cell> tellingOf(const std::vector<Cell>& cells) {
  std::vector<Cell> out;
  std::copy_if(cells.begin(), cells.end(), std::back_inserter(out), [](const Cell& c) { return c.telling; });
  return out;
}

/// One map's occupancy as a pose is judged on it: its slices dilated, its
/// cells (and the telling ones alone) and the space it encloses.
struct JudgedMap {
  std::vector<BitRaster> dilated;
  std::vector<Cell> cells, telling;
  Enclosure encloses;

  JudgedMap(const SliceStack& s, const DenseSearchParams& params)
      : dilated(dilatedSlices(s, params)),
        cells(cellsOf(s, params.wall_spread)),
        telling(tellingOf(cells)),
        encloses(s) {}
};

/// The target's and the source's JudgedMap, the two side by side where
/// `params` has threads for it: on a building at 0.05 m cells preparing them
/// took 0.2 s, one after the other.
std::pair<JudgedMap, JudgedMap> judgedMaps(const SliceStack& t, const SliceStack& s, const DenseSearchParams& params) {
  if (params.threads < 2) return {JudgedMap(t, params), JudgedMap(s, params)};
  auto source = std::async(std::launch::async, [&] { return JudgedMap(s, params); });
  JudgedMap target(t, params);
  return {std::move(target), source.get()};
}

/// What a pose is judged on, built once per pair of maps: both maps' dilated
/// occupancy, their cells and the space each saw empty.
struct PoseJudge {
  const SliceStack &target, &source;
  std::vector<BitRaster> dilated, source_dilated;
  std::vector<Cell> source_cells, target_cells;
  std::vector<Cell> source_telling, target_telling;  ///< the telling ones alone: all a score counts
  Enclosure target_encloses, source_encloses;
  BitRaster target_seen;
  const Enclosure *in_target, *in_source;  ///< null on cells too fine to read empty space

  PoseJudge(const SliceStack& t, const SliceStack& s, const DenseSearchParams& params)
      : PoseJudge(t, s, params, judgedMaps(t, s, params)) {}
  // Its enclosures are pointed at (in_target, in_source): a copy would point at the original's.
  PoseJudge(const PoseJudge&) = delete;
  PoseJudge& operator=(const PoseJudge&) = delete;

  /// The source's cells, landed on the target's raster at `landing`, at
  /// height `offset` (and slice by slice into `per_slice`, if given).
  Tally forth(const std::vector<int>& landing, int offset, std::vector<SliceLanding>* per_slice = nullptr) const {
    return countInliers(dilated, source_cells, landing, offset, source.size(), in_target, &target_seen, per_slice);
  }
  /// The target's cells landed back on the source (at `back`) at height `offset`.
  Tally backwards(const std::vector<int>& back, int offset) const {
    return countInliers(source_dilated, target_cells, back, -offset, target.size(), in_source);
  }
  /// Sets p's tally from the source's cells landed on the target (`there`)
  /// and adds the target's landed back on the source (`here`): both ways.
  static void judge(DensePose& p, const Tally& there, const Tally& here) {
    p.inliers = there.inliers, p.telling_inliers = there.telling + here.telling, p.support = there.slices;
    p.support_seen = there.slices_seen;
    p.contradicted = there.contradicted + here.contradicted;
  }
  void judge(DensePose& p, const Tally& there) const {
    judge(p, there, backwards(landings(target_cells, p.transform.inverse(), source.grid), p.offset));
  }
  /// p's score alone, on the telling cells both ways (what judge gives it).
  double score(const Rigid2D& T, int offset, const std::vector<int>& forth_telling,
               const std::vector<int>& back_telling) const {
    DensePose p{T, offset, 0};
    judge(p, countInliers(dilated, source_telling, forth_telling, offset, source.size(), in_target),
          countInliers(source_dilated, target_telling, back_telling, -offset, target.size(), in_source));
    return p.score();
  }

 private:
  /// The judge of the two maps prepared (judgedMaps), their parts moved in.
  PoseJudge(const SliceStack& t, const SliceStack& s, const DenseSearchParams& params,
            std::pair<JudgedMap, JudgedMap>&& maps)
      : target(t),
        source(s),
        dilated(std::move(maps.first.dilated)),
        source_dilated(std::move(maps.second.dilated)),
        source_cells(std::move(maps.second.cells)),
        target_cells(std::move(maps.first.cells)),
        source_telling(std::move(maps.second.telling)),
        target_telling(std::move(maps.first.telling)),
        target_encloses(std::move(maps.first.encloses)),
        source_encloses(std::move(maps.second.encloses)),
        target_seen(footprint(dilated)),
        in_target(t.grid.cell >= params.finest_empty_cell - 1e-9 ? &target_encloses : nullptr),
        in_source(t.grid.cell >= params.finest_empty_cell - 1e-9 ? &source_encloses : nullptr) {}
};

/// `poses` by transform: the indices of the poses of each distinct one, told
/// apart by their bits (so that -0.0 and a NaN are transforms of their own).
std::vector<std::vector<size_t>> byTransform(const PoseLander::Poses& poses) {
  const auto bits = [](double x) {
    uint64_t b;
    std::memcpy(&b, &x, sizeof b);
    return b;
  };
  std::map<std::tuple<uint64_t, uint64_t, uint64_t>, size_t> index;
  std::vector<std::vector<size_t>> out;
  for (size_t n = 0; n < poses.size(); ++n) {
    const Rigid2D& T = poses[n].first;
    const auto [at, added] = index.try_emplace({bits(T.yaw), bits(T.t.x()), bits(T.t.y())}, out.size());
    if (added) out.emplace_back();
    out[at->second].push_back(n);
  }
  return out;
}

/// Calls f(n, forth, back) for each of `poses` with where its transform lands
/// `forth_cells` on the target and `back_cells` on the source: landed once
/// per distinct transform (a climb's steps and a ring of shifts land each at
/// several heights, and where a transform lands the cells does not depend on
/// the height), the transforms spread over `threads`.
template <typename F>
void forEachLanding(const PoseJudge& judge, const PoseLander::Poses& poses, const std::vector<Cell>& forth_cells,
                    const std::vector<Cell>& back_cells, int threads, const F& f) {
  const std::vector<std::vector<size_t>> groups = byTransform(poses);
#pragma omp parallel for schedule(dynamic) num_threads(threads)
  for (size_t g = 0; g < groups.size(); ++g) {
    const Rigid2D& T = poses[groups[g].front()].first;
    const std::vector<int> forth = landings(forth_cells, T, judge.target.grid),
                           back = landings(back_cells, T.inverse(), judge.source.grid);
    for (size_t n : groups[g]) f(n, forth, back);
  }
}

}  // namespace dense_detail

using namespace dense_detail;

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
  forEachLanding(*judge_, poses, judge_->source_cells, judge_->target_cells, threads_,
                 [&](size_t n, const std::vector<int>& forth, const std::vector<int>& back) {
                   DensePose& p = out[n];
                   p.transform = poses[n].first, p.offset = poses[n].second;
                   PoseJudge::judge(p, judge_->forth(forth, p.offset), judge_->backwards(back, p.offset));
                 });
  return out;
}

std::vector<double> PoseLander::scores(const Poses& poses) const {
  std::vector<double> out(poses.size());
  forEachLanding(*judge_, poses, judge_->source_telling, judge_->target_telling, threads_,
                 [&](size_t n, const std::vector<int>& forth, const std::vector<int>& back) {
                   out[n] = judge_->score(poses[n].first, poses[n].second, forth, back);
                 });
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
            // A shift's value counts coincident cells: a whole number, up to
            // the transforms' rounding (thousandths). The peak is the first
            // shift, in the raster's order, at the largest whole count: on
            // sparse crops many shifts tie there, and which one a search
            // keeps is then not a matter of how the transforms round.
            const double most = std::round(scale * *std::max_element(corr.begin(), corr.end()));
            const auto least = static_cast<float>((most - 0.5) / scale);
            const size_t top = static_cast<size_t>(
                std::find_if(corr.begin(), corr.end(), [least](float v) { return v >= least; }) - corr.begin());
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
