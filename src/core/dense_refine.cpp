#include "dense_refine.hpp"

#include <cmath>

#include "bit_raster.hpp"

namespace tomomap {

namespace {

/// What the last search around one source cell found, and how far the cell
/// may move before a new search could find anything else. Once ICP is near
/// its answer the cells move by thousandths of a pixel an iteration, and the
/// window scans would find the same cells: on demo-room 83 % of them are
/// skipped, with the very correspondences of a search each time.
struct Nearest {
  Eigen::Vector2d from{0, 0};  ///< pixel position the search was made from
  int u = -1, v = -1;          ///< the nearest occupied cell in its window; u < 0: none there
  double slack = -1;           ///< [pixels]; the search stands while the cell moves less (<= 0: search again)
};

/// One slice pair: the target's occupancy and the source's cell centres.
struct PairCells {
  const BitRaster* target;
  std::vector<Eigen::Vector2d> source;  // source cell centres [m]
  std::vector<Nearest> nearest;         // one per source cell
  // This iteration's correspondences. Kept, with the joined list, so that
  // iterations reuse their memory: allocating them anew took most of what
  // was left (demo-room's refinement 0.025 s; skipping searches 0.016 s; both 0.006 s).
  Correspondences found;
};

/// The occupied cell nearest to pixel position f within the window of
/// ceil(radius) cells around it (ties: the last in row order), and how far f
/// may move before a new search could find another: another cell nearer,
/// this one out of the window, or, where there is none, a cell within
/// `radius`. Cells outside the window lie at least r + 0.5 pixels from f.
Nearest searchWindow(const BitRaster& raster, const SliceGrid& g, const Eigen::Vector2d& f, double radius) {
  const int r = static_cast<int>(std::ceil(radius));
  Nearest n;
  n.from = f;
  const int u0 = static_cast<int>(std::lround(f.x())), v0 = static_cast<int>(std::lround(f.y()));
  const double outside = r + 0.5;
  double best = outside * outside, second = best;
  const int u_lo = std::max(0, u0 - r), u_hi = std::min(g.width - 1, u0 + r);
  if (u_lo <= u_hi)
    for (int v = std::max(0, v0 - r); v <= std::min(g.height - 1, v0 + r); ++v)
      raster.forEachSet(v, u_lo, u_hi, [&](int u) {
        const double d2 = (u - f.x()) * (u - f.x()) + (v - f.y()) * (v - f.y());
        if (d2 <= best) {
          second = best;
          best = d2;
          n.u = u;
          n.v = v;
        } else if (d2 < second) {
          second = d2;
        }
      });
  if (n.u < 0) {
    n.slack = outside - radius;
    return n;
  }
  // It stays the nearest while it moves less than half the gap to the next
  // (both distances change by at most the move), and stays in the window
  // while its distance plus the move plus the centre's rounding is within r + 1.
  const double d1 = std::sqrt(best), d2 = std::sqrt(second);
  n.slack = std::min(0.5 * (d2 - d1), outside - d1);
  return n;
}

std::vector<PairCells> collectPairs(const SliceStack& target, const std::vector<BitRaster>& bits,
                                    const SliceStack& source, int offset, size_t max_cells) {
  size_t total = 0;
  for (int i = 0; i < target.size(); ++i) {
    const int j = i - offset;
    if (!target.cells[static_cast<size_t>(i)].empty() && j >= 0 && j < source.size())
      total += source.cells[static_cast<size_t>(j)].size();
  }
  // Thinning the source cells evenly keeps the cost bounded on large maps; a few
  // tens of thousands of cells already average the quantisation out.
  const size_t stride = std::max<size_t>(1, (total + max_cells - 1) / max_cells);
  std::vector<PairCells> pairs;
  const auto& g = source.grid;
  for (int i = 0; i < target.size(); ++i) {
    const int j = i - offset;
    if (target.cells[static_cast<size_t>(i)].empty() || j < 0 || j >= source.size() ||
        source.cells[static_cast<size_t>(j)].empty())
      continue;
    PairCells p{&bits[static_cast<size_t>(i)], {}, {}, {}};
    const auto& cells = source.cells[static_cast<size_t>(j)];
    for (size_t k = 0; k < cells.size(); k += stride) p.source.push_back(g.cellCentre(cells[k]));
    p.nearest.resize(p.source.size());
    pairs.push_back(std::move(p));
  }
  return pairs;
}

}  // namespace

DenseRefineResult refineOnOccupancy(const SliceStack& target, const SliceStack& source, int offset,
                                    const Rigid2D& initial, const DenseRefineParams& params) {
  return OccupancyRefiner(target, source)(offset, initial, params);
}

OccupancyRefiner::OccupancyRefiner(const SliceStack& target, const SliceStack& source)
    : target_(target), source_(source), bits_([&] {
        auto bits = std::make_shared<std::vector<BitRaster>>();
        bits->reserve(target.cells.size());
        for (const auto& cells : target.cells) bits->emplace_back(target.grid, cells);
        return bits;
      }()) {}

DenseRefineResult OccupancyRefiner::operator()(int offset, const Rigid2D& initial,
                                               const DenseRefineParams& params) const {
  const SliceStack &target = target_, &source = source_;
  DenseRefineResult result{initial, 0};
  std::vector<PairCells> pairs = collectPairs(target, *bits_, source, offset, params.max_cells);
  if (pairs.empty()) return result;
  const auto& tg = target.grid;
  Correspondences c;  // every pair's, joined in pair order for the fit
  const double cell = tg.cell;

  for (double radius_cells : params.radii_cells) {
    const double max_d2 = radius_cells * radius_cells;
    // A search made with another window does not stand for this one.
    for (PairCells& p : pairs) std::fill(p.nearest.begin(), p.nearest.end(), Nearest{});
    for (int it = 0; it < params.iterations_per_stage; ++it) {
      const Rigid2D& T = result.transform;
      const Rigid2D::Applier move = T.applier();
      // Each slice pair's correspondences on its own, in parallel, then joined
      // in pair order: the same fit as one serial pass.
#pragma omp parallel for schedule(dynamic) num_threads(params.threads)
      for (size_t n = 0; n < pairs.size(); ++n) {
        PairCells& p = pairs[n];
        p.found.source.clear();
        p.found.target.clear();
        for (size_t k = 0; k < p.source.size(); ++k) {
          const Eigen::Vector2d& s = p.source[k];
          const Eigen::Vector2d q = move(s);
          // Target pixel coordinates (centres are integers).
          const Eigen::Vector2d f = tg.toPixel(q.x(), q.y());
          Nearest& near = p.nearest[k];
          // The 1e-9 pixels keep rounding from deciding a reuse: a reused
          // search gives the very cell a new one would.
          if (!((f - near.from).norm() + 1e-9 < near.slack)) near = searchWindow(*p.target, tg, f, radius_cells);
          if (near.u < 0) continue;
          const double d2 = (near.u - f.x()) * (near.u - f.x()) + (near.v - f.y()) * (near.v - f.y());
          if (d2 > max_d2) continue;
          p.found.source.push_back(s);
          p.found.target.push_back(tg.pixelCentre(near.u, near.v));
        }
      }
      c.source.clear();
      c.target.clear();
      for (const PairCells& p : pairs) {
        c.source.insert(c.source.end(), p.found.source.begin(), p.found.source.end());
        c.target.insert(c.target.end(), p.found.target.begin(), p.found.target.end());
      }
      if (c.size() < 3) return result;
      const Rigid2D next = fitRigid2D(c);
      const bool converged = (next.t - T.t).norm() < 1e-4 * cell && std::abs(wrapAngle(next.yaw - T.yaw)) < 1e-6;
      result.transform = next;
      result.correspondences = c.size();
      if (converged) break;
    }
  }
  return result;
}

}  // namespace tomomap
