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
