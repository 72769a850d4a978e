#include <gtest/gtest.h>

#include <random>

#include "core/rigid2d.hpp"

using namespace tomomap;

static Correspondences withOutliers(const Rigid2D& truth, size_t n, double outlier_ratio, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-20, 20);
  std::normal_distribution<double> noise(0, 0.01);
  Correspondences c;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d s(u(rng), u(rng));
    c.source.push_back(s);
    if (i < static_cast<size_t>(outlier_ratio * static_cast<double>(n)))
      c.target.emplace_back(u(rng), u(rng));
    else
      c.target.push_back(truth.apply(s) + Eigen::Vector2d(noise(rng), noise(rng)));
  }
  return c;
}

TEST(Rigid2D, LeastSquaresIsExactOnNoiseFreeData) {
  const Rigid2D truth{0.7, {3, -2}};
  const Correspondences c = withOutliers(truth, 10, 0.0, 1);
  Correspondences clean;
  for (size_t i = 0; i < c.size(); ++i) {
    clean.source.push_back(c.source[i]);
    clean.target.push_back(truth.apply(c.source[i]));
  }
  const Rigid2D fit = fitRigid2D(clean);
  EXPECT_NEAR(fit.yaw, 0.7, 1e-9);
  EXPECT_NEAR(fit.t.x(), 3, 1e-9);
  EXPECT_NEAR(fit.t.y(), -2, 1e-9);
}

TEST(Rigid2D, RansacRecoversTransformWith70PercentOutliers) {
  for (uint32_t seed = 1; seed <= 20; ++seed) {
    const Rigid2D truth{-2.5 + 0.25 * seed, {seed * 1.5, -7.0}};
    const Correspondences c = withOutliers(truth, 200, 0.7, seed);
    RansacParams p;
    p.inlier_threshold = 0.1;
    const auto est = ransacRigid2D(c, p, seed);
    ASSERT_TRUE(est.has_value()) << "seed " << seed;
    EXPECT_NEAR(wrapAngle(est->transform.yaw - truth.yaw), 0, 0.005) << "seed " << seed;
    EXPECT_NEAR((est->transform.t - truth.t).norm(), 0, 0.05) << "seed " << seed;
    // The 60 true correspondences are found (a random outlier may land inside too).
    EXPECT_GE(est->inliers.size(), 60u);
    EXPECT_LE(est->inliers.size(), 63u);
  }
}

TEST(Rigid2D, RansacGivesNothingForPureNoise) {
  const Correspondences c = withOutliers({}, 100, 1.0, 5);
  RansacParams p;
  p.inlier_threshold = 0.05;
  p.min_inliers = 8;
  EXPECT_FALSE(ransacRigid2D(c, p, 1).has_value());
}

TEST(Rigid2D, RansacNeedsAtLeastTwoCorrespondences) {
  Correspondences c;
  c.source.emplace_back(0, 0);
  c.target.emplace_back(1, 1);
  EXPECT_FALSE(ransacRigid2D(c, {}, 1).has_value());
  EXPECT_FALSE(ransacRigid2D({}, {}, 1).has_value());
}

TEST(Rigid2D, SameSeedSameResult) {
  const Correspondences c = withOutliers({1.0, {2, 3}}, 100, 0.5, 9);
  const auto a = ransacRigid2D(c, {}, 42), b = ransacRigid2D(c, {}, 42);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->transform.yaw, b->transform.yaw);
  EXPECT_EQ(a->inliers, b->inliers);
}

TEST(Rigid2D, ClosedFormFitHoldsAtEveryYawAndWithASubset) {
  for (double yaw : {-3.14159, -1.5, 0.0, 1e-7, 2.0, 3.14159}) {
    const Rigid2D truth{yaw, {-40, 25}};
    Correspondences c = withOutliers(truth, 30, 0.0, 3);
    for (size_t i = 0; i < c.size(); ++i) c.target[i] = truth.apply(c.source[i]);
    c.source.emplace_back(1000, 1000);  // not in the subset: must not count
    c.target.emplace_back(-1000, 0);
    std::vector<uint32_t> subset(30);
    for (uint32_t i = 0; i < 30; ++i) subset[i] = i;
    const Rigid2D fit = fitRigid2D(c, &subset);
    EXPECT_NEAR(wrapAngle(fit.yaw - yaw), 0, 1e-9) << yaw;
    EXPECT_NEAR((fit.t - truth.t).norm(), 0, 1e-7) << yaw;
  }
}

TEST(Rigid2D, RefinementStopsAsItsRuleSays) {
  const Rigid2D truth{0.3, {1, 2}};
  const Correspondences c = withOutliers(truth, 200, 0.3, 5);
  // A start a little off, with every correspondence as inlier.
  std::vector<uint32_t> all(c.size());
  for (uint32_t i = 0; i < all.size(); ++i) all[i] = i;
  const RigidEstimate start{{0.31, {1.05, 1.95}}, all};
  // The inlier set must shrink to the true inliers: refused without allow_shrinking.
  const RigidEstimate kept = refineLeastSquares(c, start, 0.1, {5, false});
  EXPECT_EQ(kept.inliers.size(), c.size()) << "no round may lose inliers: the start stays";
  // From the inliers of a near start, it converges onto the truth.
  const Rigid2D near{0.305, {1.03, 1.98}};
  const RigidEstimate fine = refineLeastSquares(c, {near, collectInliers(c, near, 0.3)}, 0.3, {10, true});
  EXPECT_NEAR(wrapAngle(fine.transform.yaw - 0.3), 0, 0.002);
  EXPECT_LT((fine.transform.t - truth.t).norm(), 0.02);
  EXPECT_GE(fine.inliers.size(), 130u);
  EXPECT_EQ(fine.inliers, collectInliers(c, fine.transform, 0.3)) << "inliers are those of the result";
}

TEST(Rigid2D, InverseUndoesTheTransform) {
  const Rigid2D T{0.7, {1.5, -2.0}};
  for (const Eigen::Vector2d& p : {Eigen::Vector2d(0, 0), Eigen::Vector2d(3, -4), Eigen::Vector2d(-1, 2)}) {
    EXPECT_LT((T.inverse().apply(T.apply(p)) - p).norm(), 1e-12);
    EXPECT_LT((T.apply(T.inverse().apply(p)) - p).norm(), 1e-12);
  }
}
