#include "rigid2d.hpp"

#include <algorithm>
#include <random>

namespace tomomap {

Rigid2D fitRigid2D(const Correspondences& c, const std::vector<uint32_t>* subset) {
  const size_t n = subset ? subset->size() : c.size();
  auto at = [&](size_t k) { return subset ? (*subset)[k] : k; };
  Eigen::Vector2d ms = Eigen::Vector2d::Zero(), mt = Eigen::Vector2d::Zero();
  for (size_t k = 0; k < n; ++k) {
    ms += c.source[at(k)];
    mt += c.target[at(k)];
  }
  ms /= static_cast<double>(n);
  mt /= static_cast<double>(n);
  double cross = 0, dot = 0;
  for (size_t k = 0; k < n; ++k) {
    const Eigen::Vector2d s = c.source[at(k)] - ms, t = c.target[at(k)] - mt;
    cross += s.x() * t.y() - s.y() * t.x();
    dot += s.dot(t);
  }
  Rigid2D T;
  T.yaw = std::atan2(cross, dot);
  T.t = mt - Rigid2D{T.yaw, Eigen::Vector2d::Zero()}.apply(ms);
  return T;
}

RigidEstimate refineLeastSquares(const Correspondences& c, RigidEstimate est, double threshold, RefineRule rule) {
  for (int round = 0; round < rule.max_rounds && est.inliers.size() >= 2; ++round) {
    const Rigid2D refined = fitRigid2D(c, &est.inliers);
    auto next = collectInliers(c, refined, threshold);
    if (next.size() < (rule.allow_shrinking ? size_t{2} : est.inliers.size())) break;  // drifted: keep the last
    const bool same = next == est.inliers;
    est = {refined, std::move(next)};
    if (same) break;
  }
  return est;
}

std::vector<uint32_t> collectInliers(const Correspondences& c, const Rigid2D& T, double threshold) {
  std::vector<uint32_t> in;
  const double t2 = threshold * threshold;
  const Rigid2D::Applier move = T.applier();
  for (uint32_t i = 0; i < c.size(); ++i)
    if ((move(c.source[i]) - c.target[i]).squaredNorm() <= t2) in.push_back(i);
  return in;
}

std::optional<RigidEstimate> ransacRigid2D(const Correspondences& c, const RansacParams& params, uint64_t seed) {
  const size_t n = c.size();
  if (n < 2 || n < static_cast<size_t>(params.min_inliers)) return std::nullopt;
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<size_t> pick(0, n - 1);
  const double t2 = params.inlier_threshold * params.inlier_threshold;
  // Two source points closer than this give an ill-conditioned rotation.
  const double min_baseline2 = 4.0 * t2;

  size_t best_count = 0;
  Rigid2D best;
  long needed = params.max_iterations;
  for (long it = 0; it < needed; ++it) {
    const size_t a = pick(rng), b = pick(rng);
    const Eigen::Vector2d ds = c.source[b] - c.source[a], dt = c.target[b] - c.target[a];
    if (a == b || ds.squaredNorm() < min_baseline2) continue;
    // A rigid motion preserves distances: reject samples that cannot be one.
    if (std::abs(ds.norm() - dt.norm()) > 2.0 * params.inlier_threshold) continue;
    Rigid2D T;
    T.yaw = std::atan2(dt.y(), dt.x()) - std::atan2(ds.y(), ds.x());
    const double co = std::cos(T.yaw), si = std::sin(T.yaw);
    T.t = c.target[a] -
          Eigen::Vector2d(co * c.source[a].x() - si * c.source[a].y(), si * c.source[a].x() + co * c.source[a].y());
    size_t count = 0;
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Vector2d r(co * c.source[i].x() - si * c.source[i].y() + T.t.x() - c.target[i].x(),
                              si * c.source[i].x() + co * c.source[i].y() + T.t.y() - c.target[i].y());
      count += r.squaredNorm() <= t2;
    }
    if (count > best_count) {
      best_count = count;
      best = T;
      // Adaptive stopping: iterations for `confidence` of drawing one all-inlier pair.
      const double w = static_cast<double>(count) / static_cast<double>(n);
      const double p_fail = 1.0 - w * w;
      if (p_fail <= 1e-12) break;
      const double k = std::log(1.0 - params.confidence) / std::log(p_fail);
      needed = std::min<long>(params.max_iterations, static_cast<long>(std::ceil(k)));
    }
  }
  if (best_count < static_cast<size_t>(std::max(params.min_inliers, 2))) return std::nullopt;

  const RigidEstimate est = refineLeastSquares(c, {best, collectInliers(c, best, params.inlier_threshold)},
                                               params.inlier_threshold, {5, /*allow_shrinking=*/false});
  if (est.inliers.size() < static_cast<size_t>(params.min_inliers)) return std::nullopt;
  return est;
}

}  // namespace tomomap
