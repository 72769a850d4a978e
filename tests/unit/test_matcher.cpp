#include <gtest/gtest.h>

#include <random>

#include "core/candidate_decision.hpp"
#include "core/matcher.hpp"
#include "support.hpp"
#include "synth/scene.hpp"
#include "synth/synth.hpp"

using namespace tomomap;

TEST(Matcher, OppositeDirectionsGiveMutuallyInverseTransforms) {
  REQUIRE_DEMO_ROOM();
  const auto demo = test::loadDemoPair();
  const MatchParams p;
  const MatchResult ab = matchMaps(demo.map1, demo.map2, p), ba = matchMaps(demo.map2, demo.map1, p);
  ASSERT_TRUE(ab.reliable && ba.reliable);
  const PoseError e = poseError(ab.T_target_source * ba.T_target_source, Pose4{});
  EXPECT_LT(e.translation, 0.05);
  EXPECT_LT(e.yaw, 0.01);
}

TEST(Matcher, ParallelRunEqualsSerialRun) {
  REQUIRE_DEMO_ROOM();
  const auto demo = test::loadDemoPair();
  MatchParams serial, parallel;
  serial.threads = 1;
  parallel.threads = 2;
  const MatchResult a = matchMaps(demo.map1, demo.map2, serial), b = matchMaps(demo.map1, demo.map2, parallel);
  EXPECT_EQ(a.T_target_source.x, b.T_target_source.x);
  EXPECT_EQ(a.T_target_source.yaw, b.T_target_source.yaw);
  EXPECT_EQ(a.features.support, b.features.support);
  EXPECT_EQ(a.features.inliers, b.features.inliers);
  EXPECT_EQ(a.lead_sigma, b.lead_sigma);
}

TEST(Matcher, ReportsQualityAndTimings) {
  REQUIRE_DEMO_ROOM();
  const auto demo = test::loadDemoPair();
  const MatchResult r = matchMaps(demo.map1, demo.map2, MatchParams{});
  ASSERT_TRUE(r.reliable);
  const FeatureFindings& f = r.features;
  EXPECT_GT(f.support, f.runner_up_support);
  EXPECT_GE(f.inliers, 100u);
  EXPECT_GT(f.inlier_spread.x(), 0.5);  // inliers spread over the room, not one corner
  EXPECT_GT(f.inlier_spread.z(), 0.3);
  EXPECT_GT(f.slice_pairs, 1000u);  // slices with features, all against all
  EXPECT_LE(f.slice_pairs, static_cast<size_t>(r.target_slices) * r.source_slices);
  // The pair's weight in a fleet: the decision's lead, in standard deviations.
  ASSERT_TRUE(r.candidate_verdict);
  EXPECT_EQ(r.lead_sigma, r.candidate_verdict->lead_sigma);
  EXPECT_GT(r.lead_sigma, 0.0);
  EXPECT_GT(r.timings.pair_matching, 0.0);
}

TEST(Matcher, UnrelatedNoiseIsNoReliableMatch) {
  REQUIRE_DEMO_ROOM();
  const auto demo = test::loadDemoPair();
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.f, 6.f);
  Points noise;
  for (int i = 0; i < 60000; ++i) noise.emplace_back(u(rng), u(rng), u(rng) / 2);
  const MatchResult r = matchMaps(demo.map1, noise, MatchParams{});
  EXPECT_FALSE(r.reliable);
  EXPECT_FALSE(r.reason.empty());
}

TEST(Matcher, FlatMapIsNoReliableMatch) {
  Points flat;
  for (int i = 0; i < 100; ++i)
    for (int j = 0; j < 100; ++j)
      flat.emplace_back(0.05f * static_cast<float>(i), 0.05f * static_cast<float>(j * (1 + (i % 7 == 0))), 0.f);
  const MatchResult r = matchMaps(flat, flat, MatchParams{});
  EXPECT_FALSE(r.reliable);
  EXPECT_NE(r.reason.find("too few descriptive slices"), std::string::npos) << r.reason;
}

TEST(Matcher, BadInputThrows) {
  Points tiny{{0, 0, 0}, {1, 1, 1}};
  EXPECT_THROW(matchMaps(tiny, tiny, MatchParams{}), InputError);
  MatchParams zero;
  zero.grid = 0;
  EXPECT_THROW(matchMaps(tiny, tiny, zero), InputError);
  MapFeatures a, b;
  a.grid = 0.05;
  b.grid = 0.1;
  EXPECT_THROW(matchFeatures(a, b, MatchParams{}), InputError);
}

TEST(Matcher, TheSlicePairTableKeepsExactlyTheMatchesOfEachPair) {
  // Refinement reuses the table's matches instead of matching again: they must
  // be the very matches a fresh brute-force match of the pair gives.
  REQUIRE_DEMO_ROOM();
  const auto demo = test::loadDemoPair();
  const MatchParams p;
  const MapFeatures t = describeMap(demo.map1, p), s = describeMap(demo.map2, p);
  const SlicePairTable table = estimateSlicePairs(t, s, p, {});
  ASSERT_EQ(table.estimates.size(), t.slices.size() * s.slices.size());
  size_t with_estimate = 0;
  for (size_t a = 0; a < t.slices.size(); a += 7)
    for (size_t b = 0; b < s.slices.size(); b += 5) {
      const Correspondences kept = correspondencesOf(table, t, s, a, b);
      const Correspondences fresh = matchSlices(t.slices[a], s.slices[b]);
      ASSERT_EQ(kept.size(), fresh.size());
      for (size_t i = 0; i < kept.size(); ++i) {
        EXPECT_EQ(kept.source[i], fresh.source[i]);
        EXPECT_EQ(kept.target[i], fresh.target[i]);
      }
      with_estimate += table.estimates[table.index(a, b)].ok;
    }
  EXPECT_GT(with_estimate, 0u);
}

TEST(Matcher, ATieBetweenTwoHeightsIsNoReliableMatch) {
  // Two identical floors: the room fits either as well, and a pick between
  // them would be a coin flip passed off as a result.
  REQUIRE_DEMO_ROOM();
  const auto demo = test::loadDemoPair();
  Points two_floors = demo.map1;
  for (const auto& p : demo.map1) two_floors.push_back(p + Eigen::Vector3f(0, 0, 4.0f));
  const MatchResult r = matchMaps(two_floors, demo.map2, MatchParams{});
  EXPECT_FALSE(r.reliable) << "answered " << r.T_target_source.z << " m up";
  EXPECT_EQ(r.lead_sigma, 0.0) << "no answer, no weight";
  EXPECT_GT(std::abs(r.features.runner_up_offset - r.features.height_offset), 60) << "4 m apart at g 0.05";
}

namespace {

/// Every slice's features, as equal or not.
void expectSameFeatures(const MapFeatures& a, const MapFeatures& b) {
  ASSERT_EQ(a.slices.size(), b.slices.size());
  for (size_t i = 0; i < a.slices.size(); ++i) {
    EXPECT_EQ(a.slices[i].index, b.slices[i].index);
    EXPECT_EQ(a.slices[i].keypoints, b.slices[i].keypoints) << "slice " << a.slices[i].index;
    EXPECT_EQ(cv::norm(a.slices[i].descriptors, b.slices[i].descriptors, cv::NORM_HAMMING), 0.0);
  }
}

}  // namespace

TEST(Matcher, AnUpdateDescribedOnItsEarlierVersionRunsOrbOnlyWhereItChanged) {
  synth::SceneParams sp;
  sp.scale = 0.5;
  const Points before_points = synth::scanScene(synth::makeScene(sp), synth::noiseLevel("low"), 1).front().points;
  MatchParams p;
  p.grid = 0.1;
  const MapFeatures before = describeMap(before_points, p);

  // The same map again: every slice kept, nothing described anew.
  const MapFeatures same = describeMap(before_points, p, nullptr, nullptr, &before);
  EXPECT_EQ(same.kept_slices, before.occupancy.occupiedSlices());
  expectSameFeatures(same, before);

  // A cabinet inside the map: ORB runs on the slices it touched alone, and
  // the description is the one made from scratch.
  const Points updated = test::withCabinet(before_points);
  const MapFeatures fresh = describeMap(updated, p), kept = describeMap(updated, p, nullptr, nullptr, &before);
  ASSERT_TRUE(kept.occupancy.grid == fresh.occupancy.grid);
  EXPECT_GT(kept.kept_slices, 0);
  EXPECT_LT(kept.kept_slices, kept.occupancy.occupiedSlices());
  EXPECT_EQ(kept.occupancy.cells, fresh.occupancy.cells);
  expectSameFeatures(kept, fresh);

  // A map that grew beyond its raster (the robot mapped the next building
  // along) is described from scratch.
  Points grown = before_points;
  const SliceGrid& g = before.occupancy.grid;
  const auto along = static_cast<float>(g.width * g.cell);
  for (const auto& q : before_points) grown.emplace_back(q.x() + along, q.y(), q.z());
  const MapFeatures grown_kept = describeMap(grown, p, nullptr, nullptr, &before);
  EXPECT_FALSE(grown_kept.occupancy.grid == g);
  EXPECT_EQ(grown_kept.kept_slices, 0);
  expectSameFeatures(grown_kept, describeMap(grown, p));
}

// A daemon's peer map holds some slices as features, not cells, where
// those were the cheaper to send (SliceStack::partial; a map small enough
// for a dense search travels as cells throughout). The candidates land on
// the cells that came, and the decision answers on them, without a dense
// search.
TEST(Matcher, AMapWithSomeSlicesSentAsFeaturesIsAnsweredOnTheCellsItHas) {
  synth::SceneParams sp;  // the full-size building: its slices cross as cells or features, whichever is smaller
  const auto maps = synth::scanScene(synth::makeScene(sp), synth::noiseLevel("low"), sp.seed);
  MatchParams p;
  p.grid = 0.2;
  const MapFeatures target = describeMap(maps[0].points, p);
  MapFeatures source = describeMap(maps[1].points, p);
  SliceStack& o = source.occupancy;  // as the reassembler leaves it, every other slice sent as features
  o.partial = true;
  for (size_t k = 0; k < o.cells.size(); k += 2) o.cells[k].clear();
  const MatchResult r = matchFeatures(target, source, p);
  ASSERT_TRUE(r.reliable) << r.reason;
  EXPECT_GE(r.lead_sigma, kBars.significant);
  ASSERT_FALSE(r.candidates.empty());
  for (const Candidate& c : r.candidates) {
    EXPECT_FALSE(isDenseSearch(c.from)) << "no dense search of a partial stack";
    for (const SliceLanding& l : c.slices) {
      if (l.cells > 0) {
        EXPECT_EQ(l.slice % 2, 1) << "only the slices with cells land";
      }
    }
  }
  const PoseError e = poseError(r.T_target_source, Pose4::fromMatrix(maps[0].pose * maps[1].pose.inverse()));
  EXPECT_LT(e.translation, 5 * p.grid);
  EXPECT_LT(e.yaw, radians(10));
}
