#include <gtest/gtest.h>

#include "core/consensus.hpp"

using namespace tomomap;

TEST(Consensus, PicksTheLargestAgreeingCluster) {
  std::vector<Rigid2D> est;
  for (int i = 0; i < 5; ++i) est.push_back({0.50 + 0.01 * i, {10.0 + 0.02 * i, 5.0}});  // the true cluster
  for (int i = 0; i < 3; ++i) est.push_back({-1.0, {-3.0 + 0.01 * i, 2.0}});             // an aliased one
  est.push_back({2.0, {40, 40}});                                                        // a stray
  ConsensusParams p;
  const Consensus c = findConsensus(est, p);
  EXPECT_EQ(c.support(), 5u);
  EXPECT_NEAR(c.mean.yaw, 0.52, 1e-9);
  EXPECT_NEAR(c.mean.t.x(), 10.04, 1e-9);
}

TEST(Consensus, AveragesYawAcrossTheWrapAround) {
  // +179 and -179 degrees agree; their mean is 180 degrees, not 0.
  const double d = kPi / 180.0;
  const std::vector<Rigid2D> est{{179 * d, {1, 1}}, {-179 * d, {1, 1}}, {180 * d, {1, 1}}};
  const Consensus c = findConsensus(est, {});
  EXPECT_EQ(c.support(), 3u);
  EXPECT_NEAR(std::abs(wrapAngle(c.mean.yaw)), kPi, 1e-9);
}

TEST(Consensus, TiesGoToTheHeavierGroup) {
  const std::vector<Rigid2D> est{{0, {0, 0}}, {1.5, {9, 9}}};
  const Consensus c = findConsensus(est, {}, {10.0, 50.0});
  ASSERT_EQ(c.support(), 1u);
  EXPECT_EQ(c.supporters[0], 1u);
}

TEST(Consensus, EmptyInputHasNoSupport) { EXPECT_EQ(findConsensus({}, {}).support(), 0u); }

TEST(WrapAngle, MapsIntoMinusPiToPi) {
  EXPECT_NEAR(wrapAngle(3 * kPi), kPi, 1e-12);
  EXPECT_NEAR(wrapAngle(-kPi), kPi, 1e-12);  // (-pi, pi]: -pi becomes pi
  EXPECT_NEAR(wrapAngle(-3 * kPi / 2), kPi / 2, 1e-12);
  EXPECT_NEAR(wrapAngle(0.3), 0.3, 1e-15);
}
