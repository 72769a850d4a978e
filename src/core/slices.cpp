#include "slices.hpp"

#include <algorithm>
#include <optional>

#include "map_bounds.hpp"
#include "text.hpp"
#include "threads.hpp"

namespace tomomap {

cv::Mat SliceStack::image(int k, const cv::Rect& area, int pad) const {
  cv::Mat img = cv::Mat::zeros(area.height + 2 * pad, area.width + 2 * pad, CV_8U);
  const auto w = static_cast<uint32_t>(grid.width);
  for (uint32_t idx : cells[static_cast<size_t>(k)]) {
    const int u = static_cast<int>(idx % w) - area.x, v = static_cast<int>(idx / w) - area.y;
    if (u >= 0 && v >= 0 && u < area.width && v < area.height) img.at<uint8_t>(v + pad, u + pad) = 255;
  }
  return img;
}

cv::Rect SliceStack::occupiedArea(int k) const {
  const std::vector<uint32_t>& c = cells[static_cast<size_t>(k)];
  if (c.empty()) return {};
  const auto w = static_cast<uint32_t>(grid.width);
  uint32_t u0 = w, u1 = 0;
  for (uint32_t idx : c) {
    u0 = std::min(u0, idx % w);
    u1 = std::max(u1, idx % w);
  }
  const uint32_t v0 = c.front() / w, v1 = c.back() / w;  // cells are sorted by v, then u
  return {static_cast<int>(u0), static_cast<int>(v0), static_cast<int>(u1 - u0 + 1), static_cast<int>(v1 - v0 + 1)};
}

namespace {

/// Drops `stack`'s empty slices at the bottom and top; the others keep their heights.
void trimEnds(SliceStack& stack) {
  auto& cells = stack.cells;
  auto first = std::find_if(cells.begin(), cells.end(), [](const auto& c) { return !c.empty(); });
  auto last = std::find_if(cells.rbegin(), cells.rend(), [](const auto& c) { return !c.empty(); }).base();
  if (first >= last) {
    cells.clear();
    stack.seen.clear();
    return;
  }
  const auto lowest = first - cells.begin(), end = last - cells.begin();
  stack.grid.z_min = stack.grid.sliceHeight(static_cast<int>(lowest));
  cells = std::vector<std::vector<uint32_t>>(std::make_move_iterator(first), std::make_move_iterator(last));
  if (!stack.seen.empty()) {
    std::vector<bool> kept;
    for (auto k = lowest; k < end; ++k) kept.push_back(stack.seenAt(static_cast<int>(k)));
    stack.seen = std::move(kept);
  }
}

}  // namespace

SliceStack makeSlices(const Points& points, double cell, int threads, const SliceStack* keep, double sparsest) {
  if (!(cell > 0.0)) throw InputError("grid size must be positive");
  SliceStack stack;
  if (points.empty()) return stack;

  const MapBounds bounds = robustBounds(points);
  const Eigen::Vector3f lo = bounds.lo, hi = bounds.hi;
  stack.stray = bounds.outside;
  SliceGrid& g = stack.grid;
  g.cell = cell;
  g.x_min = lo.x();
  g.y_min = lo.y();
  g.z_min = lo.z();
  const double w = std::floor((hi.x() - lo.x()) / cell) + 1, h = std::floor((hi.y() - lo.y()) / cell) + 1;
  const double n = std::ceil((hi.z() - lo.z()) / cell - 0.5) + 1;
  if (w > kMaxImageSide || h > kMaxImageSide || n > kMaxImageSide) {
    const Eigen::Vector3f size = hi - lo;
    // A building is not kilometres tall: such a map is most likely in millimetres.
    const std::string units =
        size.z() > 1000.0f ? "; a map this tall is likely in millimetres: scale it to metres" : "";
    throw InputError("grid size " + fixed(cell, 4) + " m is too fine for a map of " + fixed(size.x(), 1) + " x " +
                     fixed(size.y(), 1) + " x " + fixed(size.z(), 1) + " m (more than " +
                     std::to_string(kMaxImageSide) + " cells along one axis)" + units);
  }
  g.width = static_cast<int>(w);
  g.height = static_cast<int>(h);
  size_t n_slices = static_cast<size_t>(n);
  if (keep && keep->grid.cell == cell && keep->size() > 0) {
    const SliceGrid& k = keep->grid;
    const bool within = lo.x() >= k.x_min && lo.y() >= k.y_min && k.sliceIndex(lo.z()) >= 0 &&
                        (hi.x() - k.x_min) / cell < k.width && (hi.y() - k.y_min) / cell < k.height;
    if (within) {
      g = k;
      n_slices = static_cast<size_t>(std::max(k.sliceIndex(hi.z()) + 1, keep->size()));
    }
  }

  // Each point's cell, grouped by slice (a counting sort), then each slice's
  // cells marked in a bitmap of the raster and read back in order: sorted and
  // unique in two linear passes, where sorting each slice's cells took most of
  // the slicing time on a 2 M-point building.
  const auto slices = n_slices;
  // A point's slice and cell, or nothing for a point left out as stray. Worked
  // out again in each pass rather than kept in two arrays the size of the map,
  // whose memory traffic made slicing twice as slow (0.11 against 0.055 s on a
  // 2.3 M-voxel building).
  const auto place = [&](const Eigen::Vector3f& p) -> std::optional<std::pair<size_t, uint32_t>> {
    if (bounds.outside > 0 && !bounds.contains(p)) return std::nullopt;
    const int k = std::clamp(g.sliceIndex(p.z()), 0, static_cast<int>(slices) - 1);
    const int u = std::min(static_cast<int>((p.x() - g.x_min) / cell), g.width - 1);
    const int v = std::min(static_cast<int>((p.y() - g.y_min) / cell), g.height - 1);
    return std::pair{static_cast<size_t>(k), static_cast<uint32_t>(v * g.width + u)};
  };
  std::vector<size_t> start(slices + 1, 0);
  for (const auto& p : points)
    if (const auto at = place(p)) ++start[at->first + 1];
  for (size_t k = 1; k <= slices; ++k) start[k] += start[k - 1];
  std::vector<uint32_t> grouped(start[slices]);
  {
    std::vector<size_t> next(start.begin(), start.end() - 1);
    for (const auto& p : points)
      if (const auto at = place(p)) grouped[next[at->first]++] = at->second;
  }

  stack.seen.resize(slices);
  for (size_t k = 0; k < slices; ++k) stack.seen[k] = start[k + 1] > start[k];

  const auto min_cells = static_cast<size_t>(sparsest * (g.width + g.height));
  const size_t raster_words = (static_cast<size_t>(g.width) * static_cast<size_t>(g.height) + 63) / 64;
  auto& cells = stack.cells;
  cells.resize(slices);
#pragma omp parallel num_threads(resolvedThreads(threads))
  {
    std::vector<uint64_t> marked(raster_words);
#pragma omp for schedule(dynamic)
    for (long long k = 0; k < static_cast<long long>(slices); ++k) {
      const auto first = grouped.begin() + static_cast<long>(start[static_cast<size_t>(k)]),
                 last = grouped.begin() + static_cast<long>(start[static_cast<size_t>(k) + 1]);
      if (static_cast<size_t>(last - first) < min_cells) continue;  // fewer points than cells needed
      size_t lo_word = raster_words, hi_word = 0;
      for (auto c = first; c != last; ++c) {
        marked[*c / 64] |= uint64_t{1} << (*c % 64);
        lo_word = std::min<size_t>(lo_word, *c / 64);
        hi_word = std::max<size_t>(hi_word, *c / 64);
      }
      std::vector<uint32_t>& out = cells[static_cast<size_t>(k)];
      for (size_t word = lo_word; word <= hi_word; ++word) {
        for (uint64_t bits = marked[word]; bits != 0; bits &= bits - 1)
          out.push_back(static_cast<uint32_t>(word * 64 + static_cast<size_t>(__builtin_ctzll(bits))));
        marked[word] = 0;
      }
      if (out.size() < min_cells) std::vector<uint32_t>().swap(out);
    }
  }

  trimEnds(stack);
  return stack;
}

SliceStack fullSlices(const SliceStack& stack) {
  SliceStack out = stack;
  const auto min_cells = static_cast<size_t>(kFullSlice * (stack.grid.width + stack.grid.height));
  for (auto& c : out.cells)
    if (c.size() < min_cells) std::vector<uint32_t>().swap(c);
  trimEnds(out);
  return out;
}

SliceStack pooled(const SliceStack& fine) {
  SliceStack out;
  out.grid = fine.grid;
  out.grid.cell = 2 * fine.grid.cell;
  out.grid.z_min = fine.grid.z_min + 0.5 * fine.grid.cell;
  out.grid.width = (fine.grid.width + 1) / 2;
  out.grid.height = (fine.grid.height + 1) / 2;
  out.stray = fine.stray;
  out.partial = fine.partial;
  out.cells.resize(static_cast<size_t>(fine.size() + 1) / 2);
  const auto w = static_cast<uint32_t>(fine.grid.width), W = static_cast<uint32_t>(out.grid.width);
  for (size_t k = 0; k < fine.cells.size(); ++k)
    for (uint32_t idx : fine.cells[k]) out.cells[k / 2].push_back(idx / w / 2 * W + idx % w / 2);
  if (!fine.seen.empty()) {
    out.seen.assign(out.cells.size(), false);
    for (int k = 0; k < fine.size(); ++k)
      out.seen[static_cast<size_t>(k) / 2] = out.seen[static_cast<size_t>(k) / 2] || fine.seenAt(k);
  }
  for (auto& c : out.cells) {
    std::sort(c.begin(), c.end());
    c.erase(std::unique(c.begin(), c.end()), c.end());
  }
  return out;
}

std::vector<SliceRun> seenRuns(const SliceStack& stack) {
  std::vector<SliceRun> out;
  for (int k = 0; k < stack.size(); ++k)
    if (out.empty() || out.back().seen != stack.seenAt(k))
      out.push_back({k, k, stack.seenAt(k)});
    else
      out.back().last = k;
  return out;
}

}  // namespace tomomap
