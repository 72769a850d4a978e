#pragma once
// Robust 2D rigid (rotation + translation, no scale) estimation from correspondences.
#include <cstdint>
#include <optional>

#include "types.hpp"

namespace tomomap {

struct Rigid2D {
  double yaw = 0;                               ///< [rad]
  Eigen::Vector2d t = Eigen::Vector2d::Zero();  ///< [m]

  /// The transform with its cosine and sine taken once: for many points
  /// (per point, they took a sixth of a demo-room match's instructions).
  struct Applier {
    double c, s;
    Eigen::Vector2d t;
    Eigen::Vector2d operator()(const Eigen::Vector2d& p) const {
      return {c * p.x() - s * p.y() + t.x(), s * p.x() + c * p.y() + t.y()};
    }
  };
  Applier applier() const { return {std::cos(yaw), std::sin(yaw), t}; }
  Eigen::Vector2d apply(const Eigen::Vector2d& p) const { return applier()(p); }
  /// Maps target onto source.
  Rigid2D inverse() const { return {-yaw, -Rigid2D{-yaw, Eigen::Vector2d::Zero()}.apply(t)}; }
};

/// The horizontal part of a 4-DoF pose: its x, y and yaw.
inline Rigid2D planar(const Pose4& T) { return {T.yaw, {T.x, T.y}}; }

struct Correspondences {
  std::vector<Eigen::Vector2d> source, target;  ///< matched positions [m], same length
  size_t size() const { return source.size(); }
};

struct RansacParams {
  double inlier_threshold = 0.15;  ///< [m]; the matcher sets 3 x grid
  int max_iterations = 2000;
  double confidence = 0.999;
  int min_inliers = 3;  ///< fewer inliers: no estimate
};

struct RigidEstimate {
  Rigid2D transform;              ///< maps source onto target
  std::vector<uint32_t> inliers;  ///< indices into the correspondences
};

/// Least-squares rigid fit of the selected correspondences (all of them when
/// `subset` is null); needs two or more. Closed form: with the pairs centred,
/// yaw = atan2(sum of cross products, sum of dot products), and the
/// translation takes the source centroid onto the target's.
Rigid2D fitRigid2D(const Correspondences& c, const std::vector<uint32_t>* subset = nullptr);

/// How refineLeastSquares stops.
struct RefineRule {
  int max_rounds = 5;
  /// Whether a round may keep fewer inliers than the last (down to two).
  /// RANSAC's own refinement does not: fewer means it drifted from a good
  /// sample. Starting from a consensus mean, the set may rightly shrink.
  bool allow_shrinking = false;
};

/// Alternates a least-squares fit on the inliers with re-collecting the
/// inliers within `threshold` [m], until they stop changing, `rule` stops it,
/// or fewer than two remain. The result's inliers are those of its transform.
RigidEstimate refineLeastSquares(const Correspondences& c, RigidEstimate start, double threshold, RefineRule rule);

/// RANSAC on two-point samples, then least-squares refinement on the inliers
/// (re-collecting inliers until they stop changing). `seed` makes it repeatable.
std::optional<RigidEstimate> ransacRigid2D(const Correspondences& c, const RansacParams& params, uint64_t seed);

/// Indices of correspondences that `T` maps within `threshold` [m].
std::vector<uint32_t> collectInliers(const Correspondences& c, const Rigid2D& T, double threshold);

}  // namespace tomomap
