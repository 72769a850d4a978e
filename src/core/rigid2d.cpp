#include "rigid2d.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <random>

namespace tomomap {

Rigid2D fitRigid2D(const Correspondences& c, const std::vector<uint32_t>* subset) {
  const size_t n = subset ? subset->size() : c.size();
  Eigen::Matrix2Xd src(2, n), dst(2, n);
  for (size_t k = 0; k < n; ++k) {
    const size_t i = subset ? (*subset)[k] : k;
    src.col(static_cast<Eigen::Index>(k)) = c.source[i];
    dst.col(static_cast<Eigen::Index>(k)) = c.target[i];
  }
  const Eigen::Matrix3d m = Eigen::umeyama(src, dst, false);
  Rigid2D T;
  T.yaw = std::atan2(m(1, 0), m(0, 0));
  T.t = m.block<2, 1>(0, 2);
  return T;
}

std::vector<uint32_t> collectInliers(const Correspondences& c, const Rigid2D& T, double threshold) {
  std::vector<uint32_t> in;
  const double t2 = threshold * threshold;
  for (uint32_t i = 0; i < c.size(); ++i)
    if ((T.apply(c.source[i]) - c.target[i]).squaredNorm() <= t2) in.push_back(i);
  return in;
}

std::optional<RigidEstimate> ransacRigid2D(const Correspondences& c, const RansacParams& params,
                                           uint64_t seed) {
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
    T.t = c.target[a] - Eigen::Vector2d(co * c.source[a].x() - si * c.source[a].y(),
                                        si * c.source[a].x() + co * c.source[a].y());
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

  RigidEstimate est{best, collectInliers(c, best, params.inlier_threshold)};
  for (int round = 0; round < 5; ++round) {
    const Rigid2D refined = fitRigid2D(c, &est.inliers);
    auto inliers = collectInliers(c, refined, params.inlier_threshold);
    if (inliers.size() < est.inliers.size()) break;  // refinement drifted: keep the last good one
    const bool same = inliers == est.inliers;
    est = {refined, std::move(inliers)};
    if (same) break;
  }
  if (est.inliers.size() < static_cast<size_t>(params.min_inliers)) return std::nullopt;
  return est;
}

}  // namespace tomomap
