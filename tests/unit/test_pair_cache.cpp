// Re-matching after a map update: slice pairs recalled by content give the
// answer matching everything again gives.
#include <gtest/gtest.h>

#include "core/matcher.hpp"
#include "core/pair_cache.hpp"
#include "support.hpp"

using namespace tomomap;

namespace {

void expectSameAnswer(const MatchResult& a, const MatchResult& b) {
  EXPECT_EQ(a.reliable, b.reliable);
  EXPECT_EQ(a.height_offset, b.height_offset);
  EXPECT_EQ(a.features.support, b.features.support);
  EXPECT_EQ(a.features.runner_up_support, b.features.runner_up_support);
  EXPECT_EQ(a.features.inliers, b.features.inliers);
  EXPECT_EQ(a.features.slice_pairs, b.features.slice_pairs) << "the same pairs chosen";
  EXPECT_EQ(a.T_target_source.x, b.T_target_source.x);
  EXPECT_EQ(a.T_target_source.y, b.T_target_source.y);
  EXPECT_EQ(a.T_target_source.z, b.T_target_source.z);
  EXPECT_EQ(a.T_target_source.yaw, b.T_target_source.yaw);
}

}  // namespace

TEST(PairCache, AMapUpdateReestimatesOnlyThePairsOfChangedSlicesAndAnswersAsAFreshMatch) {
  REQUIRE_DEMO_ROOM();
  const auto demo = test::loadDemoPair();
  const MatchParams p;
  const MapFeatures target = describeMap(demo.map1, p);
  const MapFeatures before = describeMap(demo.map2, p);
  const MapFeatures after = describeMap(test::withCabinet(demo.map2), p);
  size_t changed = 0;  // source slices the cabinet changed
  for (size_t i = 0; i < after.slices.size(); ++i)
    changed += i >= before.slices.size() || sliceKey(after.slices[i]) != sliceKey(before.slices[i]);
  ASSERT_GT(changed, 0u);
  ASSERT_LT(changed, after.slices.size() / 2) << "the cabinet stands 0.4-1.2 m above the floor";

  PairCache cache;
  const MatchResult first = matchFeatures(target, before, p, {}, &cache);
  EXPECT_EQ(first.features.slice_pairs_recalled, 0u) << "nothing to recall yet";
  EXPECT_EQ(cache.size(), first.features.slice_pairs);

  const MatchResult update = matchFeatures(target, after, p, {}, &cache);
  const MatchResult fresh = matchFeatures(target, after, p);
  ASSERT_TRUE(fresh.reliable) << fresh.reason;
  expectSameAnswer(update, fresh);
  EXPECT_GT(update.features.slice_pairs_recalled, update.features.slice_pairs / 2) << "most slices did not change";
  // Every pair whose source slice changed was matched again.
  EXPECT_LE(update.features.slice_pairs_recalled, target.slices.size() * (after.slices.size() - changed));
  std::printf("%zu of %zu source slices changed: %zu of %zu slice pairs recalled\n", changed, after.slices.size(),
              update.features.slice_pairs_recalled, update.features.slice_pairs);

  const MatchResult again = matchFeatures(target, after, p, {}, &cache);
  EXPECT_EQ(again.features.slice_pairs_recalled, again.features.slice_pairs) << "nothing changed";
  expectSameAnswer(again, fresh);
}

TEST(PairCache, OutcomesFromOtherSettingsAreNotRecalled) {
  REQUIRE_DEMO_ROOM();
  const auto demo = test::loadDemoPair();
  MatchParams p;
  const MapFeatures target = describeMap(demo.map1, p), source = describeMap(demo.map2, p);
  PairCache cache;
  matchFeatures(target, source, p, {}, &cache);
  p.ransac_threshold_cells = 2.0;
  const MatchResult other = matchFeatures(target, source, p, {}, &cache);
  EXPECT_EQ(other.features.slice_pairs_recalled, 0u);
  expectSameAnswer(other, matchFeatures(target, source, p));
}

TEST(PairCache, TheSameSlicesGiveTheSameOutcomeWhereverTheySitInTheirMaps) {
  REQUIRE_DEMO_ROOM();
  const auto demo = test::loadDemoPair();
  const MatchParams p;
  const MapFeatures target = describeMap(demo.map1, p), source = describeMap(demo.map2, p);
  // The source without its lowest described slice: every other slice moves down one row of the table.
  MapFeatures cropped = source;
  cropped.slices.erase(cropped.slices.begin());
  const SlicePairTable whole = estimateSlicePairs(target, source, p, {});
  const SlicePairTable part = estimateSlicePairs(target, cropped, p, {});
  for (size_t a = 0; a < whole.nt; ++a)
    for (size_t b = 1; b < whole.ns; ++b) {
      const PairEstimate& x = whole.estimates[whole.index(a, b)];
      const PairEstimate& y = part.estimates[part.index(a, b - 1)];
      ASSERT_EQ(x.ok, y.ok);
      EXPECT_EQ(x.inliers, y.inliers);
      EXPECT_EQ(x.T.yaw, y.T.yaw);
    }
}
