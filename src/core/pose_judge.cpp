#include "pose_judge.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <future>
#include <iterator>
#include <stdexcept>

namespace tomomap::dense_detail {

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

Tally countInliers(const std::vector<BitRaster>& dilated, const std::vector<Cell>& cells,
                   const std::vector<int>& landing, int offset, int source_slices, const Enclosure* enclosure,
                   const BitRaster* seen, std::vector<SliceLanding>* per_slice) {
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

template <typename Columns>
int mostInliersAt(const Columns& dilated, const std::vector<Cell>& cells, const std::vector<int>& landing, int lowest,
                  int count, std::optional<int> preferred) {
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

template int mostInliersAt(const SliceWindows&, const std::vector<Cell>&, const std::vector<int>&, int, int,
                           std::optional<int>);
template int mostInliersAt(const BitColumns&, const std::vector<Cell>&, const std::vector<int>&, int, int,
                           std::optional<int>);

BitColumns columnsOf(const std::vector<BitRaster>& dilated, const SliceGrid& grid) {
  return BitColumns(dilated, static_cast<size_t>(grid.width) * static_cast<size_t>(grid.height));
}

std::vector<BitRaster> dilatedSlices(const SliceStack& stack, const DenseSearchParams& params) {
  const BitRaster::Stamp disk = BitRaster::disk(params.inlier_radius_cells);
  std::vector<BitRaster> out;
  out.reserve(static_cast<size_t>(stack.size()));
  for (const std::vector<uint32_t>& cells : stack.cells) out.emplace_back(stack.grid, cells, disk);
  return out;
}

namespace {

/// Where a map saw anything at any height: the union of its dilated slices.
BitRaster footprint(const std::vector<BitRaster>& dilated) {
  BitRaster out;
  for (const BitRaster& slice : dilated) out.add(slice);
  return out;
}

/// The telling ones of `cells`.
std::vector<Cell> tellingOf(const std::vector<Cell>& cells) {
  std::vector<Cell> out;
  std::copy_if(cells.begin(), cells.end(), std::back_inserter(out), [](const Cell& c) { return c.telling; });
  return out;
}

}  // namespace

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

namespace {

/// The target's and the source's JudgedMap, the two side by side where
/// `params` has threads for it: on a building at 0.05 m cells preparing them
/// took 0.2 s, one after the other.
std::pair<JudgedMap, JudgedMap> judgedMaps(const SliceStack& t, const SliceStack& s, const DenseSearchParams& params) {
  if (params.threads < 2) return {JudgedMap(t, params), JudgedMap(s, params)};
  auto source = std::async(std::launch::async, [&] { return JudgedMap(s, params); });
  JudgedMap target(t, params);
  return {std::move(target), source.get()};
}

}  // namespace

PoseJudge::PoseJudge(const SliceStack& t, const SliceStack& s, const DenseSearchParams& params)
    : PoseJudge(t, s, params, judgedMaps(t, s, params)) {}

PoseJudge::PoseJudge(const SliceStack& t, const SliceStack& s, const DenseSearchParams& params,
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

}  // namespace tomomap::dense_detail
