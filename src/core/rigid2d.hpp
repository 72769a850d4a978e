#pragma once
// Robust 2D rigid (rotation + translation, no scale) estimation from correspondences.
#include <cstdint>
#include <optional>

#include "types.hpp"

namespace tomomap {

struct Rigid2D {
  double yaw = 0;                        ///< [rad]
  Eigen::Vector2d t = Eigen::Vector2d::Zero();  ///< [m]

  Eigen::Vector2d apply(const Eigen::Vector2d& p) const {
    const double c = std::cos(yaw), s = std::sin(yaw);
    return {c * p.x() - s * p.y() + t.x(), s * p.x() + c * p.y() + t.y()};
  }
};

struct Correspondences {
  std::vector<Eigen::Vector2d> source, target;  ///< matched positions [m], same length
  size_t size() const { return source.size(); }
};

struct RansacParams {
  double inlier_threshold = 0.15;  ///< [m]; the matcher sets 3 x grid
  int max_iterations = 2000;
  double confidence = 0.999;
  int min_inliers = 3;             ///< fewer inliers: no estimate
};

struct RigidEstimate {
  Rigid2D transform;             ///< maps source onto target
  std::vector<uint32_t> inliers; ///< indices into the correspondences
};

/// Least-squares rigid fit (closed form, Umeyama without scale) of the selected
/// correspondences; all of them when `subset` is null. Needs two or more.
Rigid2D fitRigid2D(const Correspondences& c, const std::vector<uint32_t>* subset = nullptr);

/// RANSAC on two-point samples, then least-squares refinement on the inliers
/// (re-collecting inliers until they stop changing). `seed` makes it repeatable.
std::optional<RigidEstimate> ransacRigid2D(const Correspondences& c, const RansacParams& params,
                                           uint64_t seed);

/// Indices of correspondences that `T` maps within `threshold` [m].
std::vector<uint32_t> collectInliers(const Correspondences& c, const Rigid2D& T, double threshold);

}  // namespace tomomap
