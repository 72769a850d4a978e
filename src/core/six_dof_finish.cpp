#include "six_dof_finish.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "text.hpp"

namespace tomomap {
namespace {

/// A cell's place on its raster's lattice: column u, row v, slice k.
struct LatticeCell {
  int u = 0, v = 0, k = 0;
};

/// The occupied cells of a stack in slice order, thinned to every `stride`-th.
std::vector<LatticeCell> latticeCells(const SliceStack& s, size_t stride) {
  std::vector<LatticeCell> out;
  const auto w = static_cast<uint32_t>(s.grid.width);
  size_t n = 0;
  for (int k = 0; k < s.size(); ++k)
    for (uint32_t index : s.cells[static_cast<size_t>(k)])
      if (n++ % stride == 0) out.push_back({static_cast<int>(index % w), static_cast<int>(index / w), k});
  return out;
}

size_t cellCount(const SliceStack& s) {
  size_t n = 0;
  for (const auto& c : s.cells) n += c.size();
  return n;
}

/// The map-frame centre [m] of a lattice cell (slices.hpp's conventions).
Eigen::Vector3d centreOf(const SliceGrid& g, const LatticeCell& c) {
  return {g.x_min + (c.u + 0.5) * g.cell, g.y_min + (c.v + 0.5) * g.cell, g.sliceHeight(c.k)};
}

/// The inverse: (sub)cell lattice position of a map-frame point; centres are integers.
Eigen::Vector3d latticeOf(const SliceGrid& g, const Eigen::Vector3d& p) {
  return {(p.x() - g.x_min) / g.cell - 0.5, (p.y() - g.y_min) / g.cell - 0.5, (p.z() - g.z_min) / g.cell};
}

/// The occupied cells of a stack, found by lattice position. A slice's cells
/// are sorted by pixel index (SliceStack), so one row's cells are one short
/// run of them: a table of where each row's run starts, over the rows the
/// slice spans, leaves a search of a few cells. A slice spanning many more
/// rows than it has cells (a peer may send a few cells on the largest
/// raster) is searched whole instead, so that the tables hold at most a few
/// entries per cell. Built in one pass over the stack's own cells; a hash of
/// every cell (24 MB of table) took 0.1 s of a room pair's 0.35 s before its
/// first sweep at 0.05 m cells, most of it page faults.
class CellLookup {
 public:
  explicit CellLookup(const SliceStack& s)
      : stack_(s), first_(static_cast<size_t>(s.size()) + 1, 0), slices_(static_cast<size_t>(s.size())) {
    const auto w = static_cast<uint32_t>(s.grid.width);
    for (size_t k = 0; k < s.cells.size(); ++k) {
      const std::vector<uint32_t>& cells = s.cells[k];
      first_[k + 1] = first_[k] + cells.size();
      if (cells.empty()) continue;
      Rows& r = slices_[k];
      r.first = cells.front() / w;
      const size_t span = cells.back() / w - r.first + 1;
      if (span > kMostRowsPerCell * cells.size()) continue;  // searched whole
      r.count = span;
      r.start = starts_.size();
      size_t n = 0;
      for (size_t v = r.first; v <= r.first + span; ++v) {  // one past the last row too
        while (n < cells.size() && cells[n] / w < v) ++n;
        starts_.push_back(static_cast<uint32_t>(n));
      }
    }
  }
  /// Index of the occupied cell at (u, v, k), or -1: its place among all of
  /// the stack's cells, slice by slice.
  int64_t find(int u, int v, int k) const {
    const SliceGrid& g = stack_.grid;
    if (u < 0 || v < 0 || k < 0 || u >= g.width || v >= g.height || k >= stack_.size()) return -1;
    const std::vector<uint32_t>& cells = stack_.cells[static_cast<size_t>(k)];
    const Rows& r = slices_[static_cast<size_t>(k)];
    auto begin = cells.begin(), end = cells.end();
    if (r.count > 0) {
      const auto row = static_cast<size_t>(v);
      if (row < r.first || row >= r.first + r.count) return -1;  // no cell of the slice on that row
      const size_t at = r.start + (row - r.first);
      begin = cells.begin() + starts_[at];
      end = cells.begin() + starts_[at + 1];
    }
    const auto key = static_cast<uint32_t>(v) * static_cast<uint32_t>(g.width) + static_cast<uint32_t>(u);
    const auto found = std::lower_bound(begin, end, key);
    if (found == end || *found != key) return -1;
    return static_cast<int64_t>(first_[static_cast<size_t>(k)] + static_cast<size_t>(found - cells.begin()));
  }
  /// The lattice position of cell `index`.
  LatticeCell at(size_t index) const {
    const auto k = static_cast<size_t>(std::upper_bound(first_.begin(), first_.end(), index) - first_.begin()) - 1;
    const uint32_t pixel = stack_.cells[k][index - first_[k]];
    const auto w = static_cast<uint32_t>(stack_.grid.width);
    return {static_cast<int>(pixel % w), static_cast<int>(pixel / w), static_cast<int>(k)};
  }

 private:
  /// A table's rows per cell at most: rooms and streets span a few rows per
  /// cell of a slice, a stray few cells on a large raster thousands.
  static constexpr size_t kMostRowsPerCell = 4;
  /// Where one slice's rows start: rows first .. first + count - 1 at
  /// starts_[start .. start + count] (one past the last row too); no rows
  /// (count 0) where the slice is searched whole or has no cells.
  struct Rows {
    size_t first = 0, count = 0, start = 0;
  };
  const SliceStack& stack_;
  std::vector<size_t> first_;  ///< per slice, the index of its first cell (and one past the last slice's)
  std::vector<Rows> slices_;
  std::vector<uint32_t> starts_;  ///< every tabled slice's row starts, in its cells
};

/// Where a stack saw anything: the columns (u, v) with a cell in some slice.
class SeenColumns {
 public:
  explicit SeenColumns(const SliceStack& s)
      : width_(s.grid.width),
        height_(s.grid.height),
        seen_(static_cast<size_t>(width_) * static_cast<size_t>(height_)) {
    for (const auto& cells : s.cells)
      for (uint32_t index : cells) seen_[index] = true;
  }
  bool has(int u, int v) const {
    return u >= 0 && v >= 0 && u < width_ && v < height_ &&
           seen_[static_cast<size_t>(v) * static_cast<size_t>(width_) + static_cast<size_t>(u)];
  }

 private:
  int width_, height_;
  std::vector<bool> seen_;
};

/// A lattice step to a neighbour, and its length [cells].
struct Offset {
  int du, dv, dk;
  double length;
};

/// Every lattice step up to `radius` cells long, shortest first (ties in a fixed
/// order): a search walks them outward and stops once no step can come nearer.
std::vector<Offset> offsetsWithin(double radius) {
  const int r = static_cast<int>(std::ceil(radius));
  std::vector<Offset> out;
  for (int dk = -r; dk <= r; ++dk)
    for (int dv = -r; dv <= r; ++dv)
      for (int du = -r; du <= r; ++du) {
        const double length = std::sqrt(static_cast<double>(du * du + dv * dv + dk * dk));
        if (length <= radius) out.push_back({du, dv, dk, length});
      }
  std::stable_sort(out.begin(), out.end(), [](const Offset& a, const Offset& b) { return a.length < b.length; });
  return out;
}

/// A target cell's surface: the plane through its neighbourhood's mean.
struct Plane {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();   ///< [m]
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  ///< unit; zero where the neighbourhood is not a plane
};

/// The target's cells, indexed, each with its plane.
struct Target {
  SliceGrid grid;
  int slices = 0;
  CellLookup cells;
  SeenColumns columns;  ///< where the target saw anything
  /// Steps out to the widest radius plus the half diagonal a position may sit off its cell.
  std::vector<Offset> search;
  /// The planes fitted so far (fitPlanes): a slot for every cell, 28 MB on
  /// a room of 600,000 cells at 0.05 m, took longer to allocate than a sweep.
  std::vector<Plane> planes;
  std::vector<uint32_t> plane_of;           ///< per cell, 1 + its plane's index in `planes`, 0 where none is fitted yet
  double normal_radius = 0, planarity = 0;  ///< SixDofFinishParams' [cells], [ratio]
};

/// Fewer cells than this within the normal radius do not fit a plane (a plane
/// crossing the radius-2 ball holds about 13).
constexpr int kMinPlaneCells = 6;

/// Fits the planes of target cells `needed` that have none yet: a plane is
/// fitted only where a correspondence needs it (a map of 700,000 cells at
/// 5 cm uses a few tens of thousands), each the same whenever it is fitted.
void fitPlanes(Target& t, const std::vector<int64_t>& needed, int threads) {
  std::vector<size_t> todo;
  for (int64_t j : needed)
    if (j >= 0 && t.plane_of[static_cast<size_t>(j)] == 0) {
      todo.push_back(static_cast<size_t>(j));
      t.plane_of[static_cast<size_t>(j)] = static_cast<uint32_t>(t.planes.size() + todo.size());
    }
  t.planes.resize(t.planes.size() + todo.size());
  const std::vector<Offset> near = offsetsWithin(t.normal_radius);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (size_t n = 0; n < todo.size(); ++n) {
    const size_t i = todo[n];
    const LatticeCell c = t.cells.at(i);
    // In lattice units (the cells are cubes): the offsets are exact integers.
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
    int count = 0;
    for (const Offset& o : near) {
      if (t.cells.find(c.u + o.du, c.v + o.dv, c.k + o.dk) < 0) continue;
      const Eigen::Vector3d d(o.du, o.dv, o.dk);
      sum += d;
      outer += d * d.transpose();
      ++count;
    }
    if (count < kMinPlaneCells) continue;
    const Eigen::Vector3d mean = sum / count;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
    eig.computeDirect(outer / count - mean * mean.transpose());
    const Eigen::Vector3d l = eig.eigenvalues();  // ascending
    if (!(l(0) <= t.planarity * l(1))) continue;  // a corner, an edge, clutter: no one normal
    Plane& plane = t.planes[t.plane_of[i] - 1];
    plane.point = centreOf(t.grid, c) + t.grid.cell * mean;
    plane.normal = eig.eigenvectors().col(0).normalized();
  }
}

/// The occupied target cell nearest to lattice position f within `radius`
/// cells, or -1: the steps are walked outward from f's cell until none can
/// come nearer than the nearest found (a step of length L lands at least
/// L - |f - its cell| from f).
int64_t nearestCell(const Target& t, const Eigen::Vector3d& f, double radius) {
  const double reach = radius + 1.0;  // farther out nothing is in reach, and rounding f could overflow
  if (!(f.x() > -reach && f.y() > -reach && f.z() > -reach && f.x() < t.grid.width + reach &&
        f.y() < t.grid.height + reach && f.z() < t.slices + reach))
    return -1;
  const int u = static_cast<int>(std::lround(f.x())), v = static_cast<int>(std::lround(f.y())),
            k = static_cast<int>(std::lround(f.z()));
  const Eigen::Vector3d off = f - Eigen::Vector3d(u, v, k);
  const double slack = off.norm();
  double best = radius;
  int64_t found = -1;
  for (const Offset& o : t.search) {
    if (o.length - slack > best) break;
    const int64_t i = t.cells.find(u + o.du, v + o.dv, k + o.dk);
    if (i < 0) continue;
    const double d = (Eigen::Vector3d(o.du, o.dv, o.dk) - off).norm();
    if (d < best || (found < 0 && d <= best)) {
      best = d;
      found = i;
    }
  }
  return found;
}

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

/// One sweep's sums over its source cells: the robust normal equations of the
/// point-to-plane residuals and the unweighted inliers' statistics.
struct Sweep {
  Matrix6d H = Matrix6d::Zero();
  Vector6d g = Vector6d::Zero();
  double weights = 0;
  size_t inliers = 0;
  double squares = 0;  ///< sum of the inliers' squared residuals [m^2]
  size_t seen = 0;     ///< cells landing in a column where the target saw anything
  size_t seen_inliers = 0;
  void add(const Sweep& o) {
    H += o.H;
    g += o.g;
    weights += o.weights;
    inliers += o.inliers;
    squares += o.squares;
    seen += o.seen;
    seen_inliers += o.seen_inliers;
  }
  /// The share of the cells in the target's columns that found their surface.
  double seenShare() const { return seen == 0 ? 0.0 : static_cast<double>(seen_inliers) / static_cast<double>(seen); }
  double rms() const { return inliers == 0 ? 0.0 : std::sqrt(squares / static_cast<double>(inliers)); }
};

/// The source cells in a fixed number of chunks, summed in chunk order: the
/// same sums, bit for bit, on any number of threads.
constexpr size_t kChunks = 64;

/// The source cells' fit at T (p_target = T * p_source) against the target's
/// planes, correspondences within `radius` cells. The unknowns are a turn about
/// `pivot` (the source cells' centroid in the target frame, scaled by `lever`,
/// their rms distance from it, so that all six are in metres and the system is
/// well conditioned far from the origin) and a shift.
Sweep sweep(Target& t, const std::vector<Eigen::Vector3d>& source, const Eigen::Matrix4d& T, double radius,
            double kernel, const Eigen::Vector3d& pivot, double lever, int threads) {
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  const Eigen::Vector3d shift = T.topRightCorner<3, 1>();
  const double kernel2 = kernel * kernel;
  std::vector<int64_t> nearest(source.size());
#pragma omp parallel for schedule(static) num_threads(threads)
  for (size_t i = 0; i < source.size(); ++i)
    nearest[i] = nearestCell(t, latticeOf(t.grid, R * source[i] + shift), radius);
  fitPlanes(t, nearest, threads);
  std::vector<Sweep> chunks(kChunks);
  const size_t per_chunk = (source.size() + kChunks - 1) / kChunks;
#pragma omp parallel for schedule(dynamic) num_threads(threads)
  for (size_t c = 0; c < kChunks; ++c) {
    Sweep& s = chunks[c];
    for (size_t i = c * per_chunk; i < std::min(source.size(), (c + 1) * per_chunk); ++i) {
      const Eigen::Vector3d p = R * source[i] + shift;
      const Eigen::Vector3d f = latticeOf(t.grid, p);
      const bool seen = std::abs(f.x()) < 1e9 && std::abs(f.y()) < 1e9 &&
                        t.columns.has(static_cast<int>(std::lround(f.x())), static_cast<int>(std::lround(f.y())));
      s.seen += seen;
      const int64_t j = nearest[i];
      if (j < 0) continue;
      const Plane& plane = t.planes[t.plane_of[static_cast<size_t>(j)] - 1];
      if (plane.normal.isZero()) continue;
      s.seen_inliers += seen;
      const double r = plane.normal.dot(p - plane.point);
      // Geman-McClure: a cell off its plane by the kernel scale pulls a quarter
      // as hard, one off by the radius a hundredth (kernel = radius / 3).
      const double w = kernel2 * kernel2 / ((kernel2 + r * r) * (kernel2 + r * r));
      Vector6d J;
      J.head<3>() = (p - pivot).cross(plane.normal) / lever;
      J.tail<3>() = plane.normal;
      s.H += w * J * J.transpose();
      s.g += w * r * J;
      s.weights += w;
      ++s.inliers;
      s.squares += r * r;
    }
  }
  Sweep total;
  for (const Sweep& s : chunks) total.add(s);
  return total;
}

/// The rotation of a rotation vector [rad].
Eigen::Matrix3d rotationOf(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  if (angle < 1e-15) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

double turnBetween(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

}  // namespace

SixDofFinish finishSixDof(const SliceStack& target, const SliceStack& source, const Eigen::Matrix4d& T_start,
                          const SixDofFinishParams& params) {
  SixDofFinish result;
  result.T_target_source = T_start;
  const size_t target_cells = cellCount(target), source_cells = cellCount(source);
  if (target_cells == 0 || source_cells == 0 || params.radii_cells.empty() || params.max_points == 0) {
    result.why_not = "too little overlap: " + std::to_string(target_cells) + " target and " +
                     std::to_string(source_cells) + " source cells";
    return result;
  }
  const double cell = target.grid.cell;
  const double last_radius = params.radii_cells.back();
  const double widest = *std::max_element(params.radii_cells.begin(), params.radii_cells.end());

  // The source cells, evenly thinned, in the source frame [m].
  const size_t stride = std::max<size_t>(1, (source_cells + params.max_points - 1) / params.max_points);
  std::vector<Eigen::Vector3d> points;
  for (const LatticeCell& c : latticeCells(source, stride)) points.push_back(centreOf(source.grid, c));
  result.points = points.size();

  Target t{target.grid,
           target.size(),
           CellLookup(target),
           SeenColumns(target),
           offsetsWithin(widest + std::sqrt(3.0) / 2),
           {},
           std::vector<uint32_t>(target_cells, 0),
           params.normal_radius_cells,
           params.planarity};

  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& p : points) centroid += p;
  centroid /= static_cast<double>(points.size());
  double spread = 0;
  for (const auto& p : points) spread += (p - centroid).squaredNorm();
  const double lever = std::max(cell, std::sqrt(spread / static_cast<double>(points.size())));

  const auto judge = [&](const Eigen::Matrix4d& T) {
    const Eigen::Vector3d pivot = T.topLeftCorner<3, 3>() * centroid + T.topRightCorner<3, 1>();
    return sweep(t, points, T, last_radius, params.kernel_share * last_radius * cell, pivot, lever, params.threads);
  };
  const Sweep before = judge(T_start);
  result.inliers_before = before.inliers;
  result.rms_before = before.rms();
  result.seen_found_before = before.seenShare();
  const auto share = [&](size_t n) {
    return fixed(100.0 * static_cast<double>(n) / static_cast<double>(points.size()), 1) + " %";
  };
  const double least = params.min_overlap * static_cast<double>(points.size());
  if (static_cast<double>(before.inliers) < least) {
    result.why_not = "too little overlap at the start: " + std::to_string(before.inliers) + " of " +
                     std::to_string(points.size()) + " cells (" + share(before.inliers) + ") within " +
                     fixed(last_radius, 1) + " cells of a target plane, need " + fixed(100 * params.min_overlap, 0) +
                     " %";
    return result;
  }

  // Gauss-Newton, stage by stage, each from the last one's answer. A small
  // damping keeps directions no surface fixes (a corridor's length) where they
  // are; it vanishes with the step, so it does not bias the answer.
  constexpr double kDamping = 1e-3;
  Eigen::Matrix4d T = T_start;
  double last_step = 0;
  bool converged = false;
  for (double radius : params.radii_cells) {
    converged = false;
    for (int it = 0; it < params.iterations_per_stage && !converged; ++it) {
      const Eigen::Vector3d pivot = T.topLeftCorner<3, 3>() * centroid + T.topRightCorner<3, 1>();
      const Sweep s = sweep(t, points, T, radius, params.kernel_share * radius * cell, pivot, lever, params.threads);
      ++result.iterations;
      if (s.inliers < 6) {
        result.why_not =
            "diverged: " + std::to_string(s.inliers) + " cells within " + fixed(radius, 1) + " cells of a target plane";
        return result;
      }
      Vector6d x = -(s.H + kDamping * s.weights * Matrix6d::Identity()).ldlt().solve(s.g);
      // Directions the surfaces hardly fix (a street's length between its
      // facades) are left where the 4-DoF answer put them: the cells' small
      // pulls along them are the maps' own distortions, not the pose.
      // (Degeneracy-aware solving: the step projected onto the eigenvectors
      // of the system that the data constrain.)
      {
        Eigen::SelfAdjointEigenSolver<Matrix6d> eig(s.H);
        const Vector6d l = eig.eigenvalues();
        Vector6d keep = Vector6d::Zero();
        for (int d = 0; d < 6; ++d) keep(d) = l(d) >= params.min_constraint * l(5) ? 1.0 : 0.0;
        const Matrix6d V = eig.eigenvectors();
        x = V * keep.asDiagonal() * V.transpose() * x;
      }
      if (!x.allFinite()) {
        result.why_not = "diverged: the 6x6 system has no solution";
        return result;
      }
      const Eigen::Matrix3d dR = rotationOf(x.head<3>() / lever);
      Eigen::Matrix4d step = Eigen::Matrix4d::Identity();
      step.topLeftCorner<3, 3>() = dR;
      step.topRightCorner<3, 1>() = pivot - dR * pivot + x.tail<3>();
      T = step * T;
      // x is in metres at the cells' rms distance: how far the step moved them.
      last_step = x.norm();
      converged = last_step < params.converged_cells * cell;
    }
  }

  const Eigen::Matrix3d R0 = T_start.topLeftCorner<3, 3>(), R = T.topLeftCorner<3, 3>();
  result.roll_pitch_corrected =
      std::acos(std::clamp((R * Eigen::Vector3d::UnitZ()).dot(R0 * Eigen::Vector3d::UnitZ()), -1.0, 1.0));
  double moved = 0;
  for (const auto& p : points) moved += ((T - T_start) * p.homogeneous()).norm();
  result.moved = moved / static_cast<double>(points.size());
  const double turned = turnBetween(R0, R);
  if (!converged && last_step > 0.1 * cell) {
    result.why_not = "diverged: still moving the cells " + fixed(last_step / cell, 2) + " cells an iteration after " +
                     std::to_string(result.iterations) + " iterations";
    return result;
  }
  if (result.moved > params.max_move_cells * cell || turned > params.max_turn) {
    result.why_not = "diverged: it moved the cells " + fixed(result.moved, 2) + " m on average and turned " +
                     fixed(degrees(turned), 2) + " deg; a finish moves at most " +
                     fixed(params.max_move_cells * cell, 2) + " m and turns " + fixed(degrees(params.max_turn), 2) +
                     " deg";
    return result;
  }
  const Sweep after = judge(T);
  result.inliers_after = after.inliers;
  result.rms_after = after.rms();
  result.seen_found_after = after.seenShare();
  // A finish holds where it left the maps fitting no worse than it found
  // them: of the source's cells landing where the target saw anything, no
  // fewer on the target's surfaces. That share is not a bar of its own: at
  // the right pose real SLAM maps show 0.34-0.52 (trees, people, what one
  // robot saw from a side the other did not), generated rooms 0.93; the
  // decision judged the pose, the finish only sharpens it.
  if (result.seen_found_after < result.seen_found_before - params.seen_found_noise) {
    result.why_not = "the fit got worse: " + fixed(100 * result.seen_found_before, 1) + " -> " +
                     fixed(100 * result.seen_found_after, 1) +
                     " % of the cells landing where the target saw anything lie on its surfaces";
    return result;
  }
  result.held = true;
  result.T_target_source = T;
  return result;
}

}  // namespace tomomap
