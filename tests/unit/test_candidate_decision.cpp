#include <gtest/gtest.h>

#include <cmath>

#include "core/candidate_decision.hpp"
#include "core/height_offsets.hpp"
#include "core/lead_sigma.hpp"

using namespace tomomap;

namespace {

/// A candidate at (x, y, yaw) whose source slices 0..n-1 each land `on`
/// telling cells of `telling` and contradict `contradicted`.
Candidate landing(double x, double y, double yaw, int n, const std::vector<uint32_t>& on, uint32_t telling = 100,
                  uint32_t contradicted = 0) {
  Candidate c;
  c.landed.transform = Rigid2D{yaw, Eigen::Vector2d(x, y)};
  for (int k = 0; k < n; ++k) {
    SliceLanding s;
    s.slice = k;
    s.cells = s.telling = telling;
    s.on = s.telling_on = on[static_cast<size_t>(k) % on.size()];
    s.contradicted = contradicted;
    c.slices.push_back(s);
  }
  return c;
}

/// The decision on `candidates` and `searches`, for maps of `grid` whose
/// source raster is centred at the origin.
CandidateVerdict decide(std::vector<Candidate> candidates, std::vector<SearchLead> searches, double grid = 0.1) {
  DecisionEvidence e;
  e.candidates = std::move(candidates);
  e.searches = std::move(searches);
  e.grid = grid;
  return decideOnCandidates(e, MatchParams{});
}

}  // namespace

TEST(CandidateDecision, ALeadCountsByItsSlicesSpreadAndNumber) {
  EXPECT_EQ(sliceLeadSigma({}), 0.0);
  EXPECT_EQ(sliceLeadSigma({5.0}), 0.0) << "one slice says nothing of chance";
  EXPECT_EQ(sliceLeadSigma({-1, -2, -3, -4}), 0.0);
  // The same t (3.43) over 4 slices and over 50, slices that do not echo
  // each other (they alternate about the lead): the few count for less.
  std::vector<double> few, many;
  for (int k = 0; k < 4; ++k) few.push_back(k % 2 ? 2.0 + 1.00965 : 2.0 - 1.00965);
  for (int k = 0; k < 50; ++k) many.push_back(k % 2 ? 2.0 + 4.08 : 2.0 - 4.08);
  EXPECT_NEAR(sliceLeadSigma(few), 2.04, 0.02);   // 3 degrees of freedom: tail 2.1 %
  EXPECT_NEAR(sliceLeadSigma(many), 3.23, 0.02);  // 49 degrees of freedom
}

// Neighbouring slices see the same walls: a lead that rises and falls
// slowly with height is fewer independent looks than its slices.
TEST(CandidateDecision, SlicesThatEchoEachOtherCountForFewer) {
  std::vector<double> wave, shuffled;
  for (int k = 0; k < 30; ++k) wave.push_back(1.0 + 2.0 * std::sin(k / 4.0));
  for (int k = 0; k < 30; ++k) shuffled.push_back(wave[static_cast<size_t>(k % 2 ? k / 2 : 29 - k / 2)]);
  EXPECT_GE(sliceLeadSigma(shuffled), 3.0) << "the same differences in no order: 30 looks";
  EXPECT_NEAR(sliceLeadSigma(wave), 0.76, 0.02) << "a slow wave is a few looks, not 30: 2 at the least";
  EXPECT_GT(sliceLeadSigma(shuffled), sliceLeadSigma(wave));
  // A lead that grows steadily with height is a difference in the mean, not
  // an echo: the straight line is taken out before the slices are compared.
  std::vector<double> ramp;
  for (int k = 0; k < 30; ++k) ramp.push_back(1.0 + 0.1 * k + (k % 2 ? 0.5 : -0.5));
  EXPECT_NEAR(sliceLeadSigma(ramp), 7.38, 0.02);  // the plain t over 30 slices: t = 12.9
  EXPECT_DOUBLE_EQ(sliceLeadSigma({1.0, 2.0, 3.0}), signFlipLeadSigma({1.0, 2.0, 3.0})) << "too few to tell";
  EXPECT_LT(sliceLeadSigma({0.2, 0.2001, 0.2}), 2.0) << "three slices alike are three slices, not a certainty";
  EXPECT_EQ(sliceLeadSigma({}), 0.0);
  const std::vector<double> steady(30, 0.1);  // the same lead on every slice, to rounding
  EXPECT_GT(sliceLeadSigma(steady), 30.0);
}

// The features' votes are small counts, often the same from slice to slice:
// a t over them reads one vote more on each of two slices as certain.
TEST(CandidateDecision, AVotesLeadCountsByItsSlicesNotByHowAlikeTheyAre) {
  EXPECT_NEAR(signFlipLeadSigma({1, 1}), std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(signFlipLeadSigma(std::vector<double>(9, 2.0)), 3.0, 1e-12) << "9 slices alike: 3 sigma";
  EXPECT_NEAR(signFlipLeadSigma({3, -1, 2, 0, 4}), 8.0 / std::sqrt(30.0), 1e-12);
  EXPECT_EQ(signFlipLeadSigma({}), 0.0);
  EXPECT_EQ(signFlipLeadSigma({-1, 1}), 0.0);
  EXPECT_EQ(signFlipLeadSigma({1, -2}), 0.0);

  // A LiDAR crop: the most voted-for pose has one estimate on each of two
  // source slices, the pose elsewhere none, and the occupancy tells neither.
  Candidate voted = landing(0, 0, 0, 2, {40}), other = landing(20, 0, 2.0, 2, {40});
  voted.feature_votes = {1, 1};
  other.feature_votes = {0, 0};
  const CandidateVerdict v = decide({voted, other}, {}, 0.1);
  EXPECT_EQ(v.answer, -1) << v.reason;
  EXPECT_NE(v.reason.find("by 1.4 sigma over 2 source slices"), std::string::npos) << v.reason;
}

TEST(CandidateDecision, TheBestAnswersWhereItLeadsEveryPlaceElsewhereBeyondChance) {
  std::vector<Candidate> c{landing(0, 0, 0, 20, {60, 70, 65}), landing(5, 0, 0, 20, {30, 20, 25}),
                           // within one tolerance (5 cells, 0.5 m) of the best: the same place, not a rival
                           landing(0.3, 0, 0, 20, {58, 71, 66})};
  const CandidateVerdict v = decide(c, {}, 0.1);
  ASSERT_EQ(v.answer, 0) << v.reason;
  EXPECT_EQ(v.on, CandidateVerdict::On::occupancy);
  EXPECT_GE(v.lead_sigma, kBars.significant);
  EXPECT_EQ(v.slices, 20);
}

TEST(CandidateDecision, TwoPlacesThatLandAlikeAreNoAnswer) {
  std::vector<Candidate> c{landing(0, 0, 0, 20, {60, 50, 70}), landing(0, 0, 3.1, 20, {55, 65, 58})};
  const CandidateVerdict v = decide(c, {}, 0.1);
  EXPECT_EQ(v.answer, -1);
  EXPECT_NE(v.reason.find("sigma over 20 slices (need 3)"), std::string::npos) << v.reason;
  // One candidate alone has nothing to be clear of.
  const CandidateVerdict alone = decide({c[0]}, {}, 0.1);
  EXPECT_EQ(alone.answer, -1);
  EXPECT_NE(alone.reason.find("no candidate elsewhere"), std::string::npos) << alone.reason;
  EXPECT_EQ(decide({}, {}, 0.1).answer, -1);
}

TEST(CandidateDecision, WhereTheOccupancyDoesNotTellTheFeaturesVotesDoUnlessItTellsAgainstThem) {
  // A street: two poses 3 m apart along the facades land alike; the slice
  // pairs agree with the second on every slice.
  Candidate along = landing(3, 0, 0, 20, {60, 50, 70}), right = landing(0, 0, 0, 20, {55, 65, 58});
  along.feature_votes.assign(20, 0);
  right.feature_votes.assign(20, 0);
  for (size_t k = 0; k < 20; ++k) {
    right.feature_votes[k] = 3 + static_cast<int>(k % 2);
    along.feature_votes[k] = k % 3 == 0 ? 1 : 0;
  }
  CandidateVerdict v = decide({along, right}, {}, 0.1);
  ASSERT_EQ(v.answer, 1) << v.reason;
  EXPECT_EQ(v.on, CandidateVerdict::On::feature_votes);
  EXPECT_GE(v.lead_sigma, kBars.significant);
  // A third pose elsewhere that lands far more, slice by slice, tells against them.
  const Candidate clear = landing(-6, 2, 1.0, 20, {95, 90, 97});
  v = decide({along, right, clear}, {}, 0.1);
  EXPECT_EQ(v.answer, 2) << "the occupancy's clear best answers first: " << v.reason;
  EXPECT_EQ(v.on, CandidateVerdict::On::occupancy);
}

// Where no candidate lands a telling cell (a peer map whose slices all came
// as features), the features' votes alone decide, and a candidate with no
// rival elsewhere leads a place with no votes.
TEST(CandidateDecision, WhereNoCandidateLandsTheVotesAloneDecide) {
  Candidate right = landing(0, 0, 0, 0, {0}), other = landing(4, 1, 0.5, 0, {0});
  right.feature_votes.assign(12, 2);
  other.feature_votes.assign(12, 0);
  other.feature_votes[3] = 1;
  CandidateVerdict v = decide({other, right}, {}, 0.1);
  ASSERT_EQ(v.answer, 1) << v.reason;
  EXPECT_EQ(v.on, CandidateVerdict::On::feature_votes);
  v = decide({right}, {}, 0.1);
  EXPECT_EQ(v.answer, 0) << "alone, against no votes: " << v.reason;
  // Two source slices' votes are no lead beyond chance.
  right.feature_votes.assign(2, 5);
  v = decide({right}, {}, 0.1);
  EXPECT_EQ(v.answer, -1);
  EXPECT_NE(v.reason.find("leads no votes elsewhere (no candidate is) by 1.4 sigma over 2 source slices"),
            std::string::npos)
      << v.reason;
}

// On maps finer than 0.1 m the place is judged on pooled occupancy, which
// reads empty space but not a pose a cell or two off; the pose answered is
// the one at that place that lands the most on the maps' own cells.
TEST(CandidateDecision, AtItsPlaceThePoseAnsweredLandsTheMostOnTheMapsOwnCells) {
  const auto pooledAs = [](Candidate fine, const Candidate& pooled) {
    fine.pooled_slices = pooled.slices;
    return fine;
  };
  std::vector<Candidate> c{// lands the most pooled; two cells off, so less on its own cells
                           pooledAs(landing(0.1, 0, 0, 40, {40, 45}), landing(0.1, 0, 0, 20, {70, 75})),
                           pooledAs(landing(0, 0, 0, 40, {60, 65}), landing(0, 0, 0, 20, {68, 74})),  // the same place
                           pooledAs(landing(5, 0, 0, 40, {20, 25}), landing(5, 0, 0, 20, {30, 35}))};
  const CandidateVerdict v = decide(c, {}, 0.05);
  ASSERT_EQ(v.answer, 1) << v.reason;
  EXPECT_EQ(v.on, CandidateVerdict::On::occupancy);
  EXPECT_EQ(v.slices, 20) << "the place's lead, on the pooled slices";
  // Unpooled (0.1 m and coarser) the best answers as it lands.
  for (Candidate& k : c) k.slices = k.pooled_slices, k.pooled_slices.clear();
  EXPECT_EQ(decide(c, {}, 0.1).answer, 0);
}

TEST(CandidateDecision, EmptySpaceTheOtherMapSawCountsAgainstAPose) {
  // The half-turned room lands more cells but twice as many of its cells in space the target saw empty.
  std::vector<Candidate> c{landing(0, 0, 3.1, 20, {80, 85, 82}, 100, 30), landing(0, 0, 0, 20, {60, 62, 61}, 100, 0)};
  const CandidateVerdict v = decide(c, {}, 0.1);
  EXPECT_EQ(v.answer, 1) << v.reason;
}

namespace {

/// A dense search's word on its own best pose at (x, y, yaw): `best` telling
/// cells landed over 6 slices, its next pose `next`.
SearchLead searchLead(Candidate::From from, double x, double y, double yaw, size_t best, double next) {
  SearchLead s;
  s.from = from;
  s.found.found = true;
  s.found.best.transform = Rigid2D{yaw, Eigen::Vector2d(x, y)};
  s.found.best.telling_inliers = best;
  s.found.best.support = s.found.best.support_seen = 6;
  s.found.next_score = next;
  return s;
}

}  // namespace

TEST(CandidateDecision, TheOccupancysBestPlaceAnswersWhereADenseSearchAndAFeatureEstimateFindItToo) {
  // An RGB-D crop: the right pose and a copy of it 0.6 m along a wall land
  // almost alike over few slices, not clear of each other.
  Candidate right = landing(0, 0, 0, 6, {62, 55, 70}), along = landing(0.6, 0, 0, 6, {60, 56, 66});
  right.from = Candidate::From::search_wide;
  along.from = Candidate::From::search_pooled;
  right.feature_votes = {0, 1, 0};
  // The wide search's own best pose, 1.5x its next: beyond chance (6.3 sigma).
  const std::vector<SearchLead> wide{searchLead(Candidate::From::search_wide, 0, 0, 0, 600, 400)};
  CandidateVerdict v = decide({right, along}, wide, 0.1);
  ASSERT_EQ(v.answer, 0) << v.reason;
  EXPECT_EQ(v.on, CandidateVerdict::On::corroborated);
  EXPECT_LT(v.lead_sigma, kBars.significant) << "the occupancy alone does not tell them apart";

  // The search's best pose within chance of its next (1.04x, 0.7 sigma) ranks nothing.
  std::vector<SearchLead> close = wide;
  close[0].found.next_score = 600 / 1.04;
  v = decide({right, along}, close, 0.1);
  EXPECT_EQ(v.answer, -1);
  EXPECT_NE(v.reason.find("search_wide's best pose is at its place but within chance of its next (1.04x, 0.7 sigma)"),
            std::string::npos)
      << v.reason;
  // Another search clear of its next, whose best pose lies elsewhere, does not stand in for it.
  std::vector<SearchLead> elsewhere = close;
  elsewhere.push_back(searchLead(Candidate::From::search_pooled, 0.6, 0, 0, 900, 300));
  v = decide({right, along}, elsewhere, 0.1);
  EXPECT_EQ(v.answer, -1) << "search_pooled's best pose is the copy along the wall";
  // Beyond chance by however small a ratio: 6,000 cells against 5,400 is 1.11x, 5.6 sigma.
  std::vector<SearchLead> many = wide;
  many[0].found.best.telling_inliers = 6000;
  many[0].found.next_score = 5400;
  v = decide({right, along}, many, 0.1);
  EXPECT_EQ(v.answer, 0) << v.reason;
  EXPECT_EQ(v.on, CandidateVerdict::On::corroborated);

  // A pose the other map's empty space contradicts is not a right answer
  // with its copy: 24 % as many telling cells in that space as on its
  // occupancy (both ways, as the climb lands it) against at most 20 %.
  Candidate contradicted = right;
  contradicted.landed.telling_inliers = 1000, contradicted.landed.contradicted = 240;
  v = decide({contradicted, along}, wide, 0.1);
  EXPECT_EQ(v.answer, -1);
  EXPECT_NE(v.reason.find("it lands 24 % as many telling cells in space the other map saw empty"), std::string::npos)
      << v.reason;
  contradicted.landed.contradicted = 200;
  EXPECT_EQ(decide({contradicted, along}, wide, 0.1).answer, 0);

  // No slice-pair estimate there: the occupancy's word alone, which is not clear.
  Candidate unvoted = right;
  unvoted.feature_votes.clear();
  v = decide({unvoted, along}, wide, 0.1);
  EXPECT_EQ(v.answer, -1);
  EXPECT_NE(v.reason.find("no slice-pair estimate of the features agrees"), std::string::npos) << v.reason;

  // The dense search's own best is the copy along the wall (rank 0), this is
  // its runner-up: the two looks at the occupancy disagree.
  Candidate runner_up = right;
  runner_up.rank = 1;
  along.rank = 0;
  v = decide({runner_up, along}, wide, 0.1);
  EXPECT_EQ(v.answer, -1);
  EXPECT_NE(v.reason.find("no dense search's best pose is at its place"), std::string::npos) << v.reason;

  // The features' own answer is not a dense search: it corroborates nothing by itself.
  Candidate from_features = right;
  from_features.from = Candidate::From::features;
  along.rank = 1;
  along.from = Candidate::From::feature_rival;
  v = decide({from_features, along}, wide, 0.1);
  EXPECT_EQ(v.answer, -1);
  EXPECT_NE(v.reason.find("no dense search of the occupancy"), std::string::npos) << v.reason;
}

// A room at g 0.1: the right pose and a copy of it a wall along land alike
// slice by slice, and no feature estimate tells them apart; the search of
// the whole occupancy puts its own best pose at the right one, far ahead of
// its next, and finds it again with the maps' roles swapped.
TEST(CandidateDecision, TheOccupancysBestPlaceAnswersWhereASearchsClearBestIsFoundAgainBothWays) {
  const std::vector<Candidate> c{landing(0, 0, 0, 6, {62, 55, 70}), landing(0.6, 0, 0, 6, {60, 56, 66})};
  std::vector<SearchLead> searches{searchLead(Candidate::From::search_at_grid, 0.05, 0, 0, 900, 300)};
  CandidateVerdict v = decide(c, searches, 0.1);
  EXPECT_EQ(v.answer, -1);
  ASSERT_TRUE(v.needs_look.has_value()) << "the look decides, so the decision asks for it: " << v.reason;
  EXPECT_EQ(*v.needs_look, Candidate::From::search_at_grid);

  searches[0].look = SecondLook{true, true, 0.02};
  v = decide(c, searches, 0.1);
  ASSERT_EQ(v.answer, 0) << v.reason;
  EXPECT_EQ(v.on, CandidateVerdict::On::second_look);
  EXPECT_FALSE(v.needs_look);
  EXPECT_NEAR(v.lead_sigma, 600 / std::sqrt(1200.0), 1e-9) << "the search's lead over its next";

  // Asked again the other way round, the search finds another place: no answer, and the reason says so.
  searches[0].look = SecondLook{true, false, 2.4};
  v = decide(c, searches, 0.1);
  EXPECT_EQ(v.answer, -1);
  EXPECT_FALSE(v.needs_look);
  EXPECT_NE(v.reason.find("search_at_grid with the maps' roles swapped found another place, 2.40 m apart"),
            std::string::npos)
      << v.reason;

  // The pooled search's best pose is there too: where the grid's look fails, the decision asks for the pooled one's.
  SearchLead pooled = searches[0];
  pooled.from = Candidate::From::search_pooled;
  pooled.pooling = 2;
  pooled.look.reset();
  searches.push_back(pooled);
  v = decide(c, searches, 0.1);
  ASSERT_TRUE(v.needs_look.has_value()) << v.reason;
  EXPECT_EQ(*v.needs_look, Candidate::From::search_pooled);
  searches[1].look = SecondLook{false, false, 0.0};
  v = decide(c, searches, 0.1);
  EXPECT_EQ(v.answer, -1);
  EXPECT_NE(v.reason.find("search_pooled with the maps' roles swapped found no pose"), std::string::npos) << v.reason;
}

TEST(CandidateDecision, ASearchsBestPoseNotClearOfItsNextOrClearlyElsewhereDoesNotAnswer) {
  const std::vector<Candidate> c{landing(0, 0, 0, 6, {62, 55, 70}), landing(0.6, 0, 0, 6, {60, 56, 66})};
  SearchLead grid = searchLead(Candidate::From::search_at_grid, 0, 0, 0, 900, 300);
  grid.look = SecondLook{true, true, 0.0};

  // 1.3x ahead of its next: not clear of it, however often it is found again.
  SearchLead close = grid;
  close.found.next_score = 900 / 1.3;
  CandidateVerdict v = decide(c, {close}, 0.1);
  EXPECT_EQ(v.answer, -1);
  EXPECT_FALSE(v.needs_look);
  // Clear, but on fewer slices than min_support: a floor alone.
  SearchLead thin = grid;
  thin.found.best.support = MatchParams{}.min_support - 1;
  v = decide(c, {thin}, 0.1);
  EXPECT_EQ(v.answer, -1);
  EXPECT_FALSE(v.needs_look);

  // The wide search is not looked at again (it never answers alone), but
  // its clear best pose elsewhere tells against the place: a real RGB-D
  // crop's pooled best, found again both ways, was wrong where the grid's
  // best lay elsewhere, 1.96x ahead.
  const SearchLead wide_elsewhere = searchLead(Candidate::From::search_wide, 3, 1, 1.5, 500, 200);
  v = decide(c, {grid, wide_elsewhere}, 0.1);
  EXPECT_EQ(v.answer, -1);
  EXPECT_NE(v.reason.find("search_wide's best pose lies elsewhere, 2.50x ahead of its next"), std::string::npos)
      << v.reason;
  const SearchLead wide_here = searchLead(Candidate::From::search_wide, 0, 0, 0, 500, 200);
  v = decide(c, {wide_here}, 0.1);
  EXPECT_EQ(v.answer, -1) << "the wide search alone has no second look";
  EXPECT_FALSE(v.needs_look);
  v = decide(c, {wide_here, grid}, 0.1);
  EXPECT_EQ(v.answer, 0) << v.reason;

  // A pooled search's best pose is a whole number of pooled slices high: a
  // slice above the place is still at it.
  SearchLead pooled = grid;
  pooled.from = Candidate::From::search_pooled;
  pooled.pooling = 2;
  pooled.found.best.offset = kSmearSlices / 2 + 1;
  v = decide(c, {pooled}, 0.1);
  EXPECT_EQ(v.answer, 0) << v.reason;
}

// The pose a second look vouches for is the search's own best; where
// another candidate at its place lands a little more (a real RGB-D crop at
// g 0.1, sunrgbd-room-38: the grid's runner-up climbed onto one slice 0.64 m
// off and landed more than the wide search's best, 0.10 m off), the
// search's pose is answered, not the one that lands the most.
TEST(CandidateDecision, ASecondLookAnswersThePoseItFoundAgain) {
  Candidate most = landing(0.3, 0, 0, 6, {63, 54, 71}), searched = landing(0, 0, 0, 6, {62, 55, 70}),
            copy = landing(1.2, 0, 0, 6, {60, 56, 66});
  most.from = Candidate::From::search_pooled, most.rank = 1;
  searched.from = Candidate::From::search_at_grid;
  copy.from = Candidate::From::search_wide;
  SearchLead grid = searchLead(Candidate::From::search_at_grid, 0, 0, 0, 900, 300);
  grid.look = SecondLook{true, true, 0.02};
  const CandidateVerdict v = decide({most, searched, copy}, {grid}, 0.1);
  ASSERT_EQ(v.on, CandidateVerdict::On::second_look) << v.reason;
  EXPECT_EQ(v.answer, 1) << "the grid's own best, as it climbed";
}
