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

namespace {

/// A dense search's word on its own best pose at (x, y, yaw): `best` telling
/// cells landed over 6 slices, its next pose `next`. The wide search judges
/// its poses on the occupancy the candidates are landed on, as in a match.
SearchLead searchLead(Candidate::From from, double x, double y, double yaw, size_t best, double next,
                      std::optional<SecondLook> look = {}) {
  SearchLead s;
  s.from = from;
  s.found.found = true;
  s.found.best.transform = Rigid2D{yaw, Eigen::Vector2d(x, y)};
  s.found.best.telling_inliers = best;
  s.found.best.support = s.found.best.support_seen = 6;
  s.found.next_score = next;
  s.look = look;
  s.judged_as_candidates = from == Candidate::From::search_wide;
  return s;
}

/// `c` from `from`, of rank `rank`, with `votes` (by source slice).
Candidate as(Candidate c, Candidate::From from, int rank = 0, std::vector<int> votes = {}) {
  c.from = from;
  c.rank = rank;
  c.feature_votes = std::move(votes);
  return c;
}

/// `fine` judged, as on maps finer than 0.1 m, on `pooled`'s slices.
Candidate pooledAs(Candidate fine, const Candidate& pooled) {
  fine.pooled_slices = pooled.slices;
  return fine;
}

/// `c` landed with `telling` telling cells, as the search whose poses are judged so would score it.
Candidate scoring(Candidate c, size_t telling) {
  c.landed.telling_inliers = telling;
  return c;
}

/// `c` landing `contradicted` telling cells in the target's empty space per 1,000 on its occupancy.
Candidate contradicting(Candidate c, uint32_t contradicted) {
  c.landed.telling_inliers = 1000, c.landed.contradicted = contradicted;
  return c;
}

/// Votes of a street's slice pairs: 3-4 on every one of 20 source slices for
/// the right pose, 1 on every third for a pose along the facades.
std::vector<int> streetVotes(bool right) {
  std::vector<int> v(20);
  for (size_t k = 0; k < v.size(); ++k) v[k] = right ? 3 + static_cast<int>(k % 2) : (k % 3 == 0 ? 1 : 0);
  return v;
}

using From = Candidate::From;
using On = CandidateVerdict::On;

/// One row of the decision's truth table: the evidence, and what it decides.
struct Row {
  const char* what;
  std::vector<Candidate> candidates;
  std::vector<SearchLead> searches;
  double grid;
  int answer;          ///< -1: no reliable match
  On on;               ///< where it answers
  const char* reason;  ///< a part of why not, where it does not
  std::optional<From> needs_look = std::nullopt;
};

/// A room's right pose and a copy of it 0.6 m along a wall, landing alike over 6 slices.
Candidate right() { return landing(0, 0, 0, 6, {62, 55, 70}); }
Candidate along() { return landing(0.6, 0, 0, 6, {60, 56, 66}); }
/// The wide search's own best pose at the right one, 1.5x its next (6.3 sigma).
SearchLead wideAtRight() { return searchLead(From::search_wide, 0, 0, 0, 600, 400); }
/// The search at the grid's, 3x its next, found again with the maps' roles swapped.
SearchLead gridFoundAgain() {
  return searchLead(From::search_at_grid, 0, 0, 0, 900, 300, SecondLook{true, true, 0.02});
}

std::vector<Row> truthTable() {
  const std::vector<int> one_vote{0, 1, 0};
  return {
      // 3. The occupancy: the candidate that lands the most, slice by slice, beyond chance of every place elsewhere.
      {"the best lands beyond chance more than every place elsewhere (one 0.3 m along is the same place)",
       {landing(0, 0, 0, 20, {60, 70, 65}), landing(5, 0, 0, 20, {30, 20, 25}), landing(0.3, 0, 0, 20, {58, 71, 66})},
       {},
       0.1,
       0,
       On::occupancy,
       ""},
      {"two places that land alike",
       {landing(0, 0, 0, 20, {60, 50, 70}), landing(0, 0, 3.1, 20, {55, 65, 58})},
       {},
       0.1,
       -1,
       On::occupancy,
       "sigma over 20 slices (need 3)"},
      {"one candidate has nothing to be clear of",
       {landing(0, 0, 0, 20, {60, 50, 70})},
       {},
       0.1,
       -1,
       On::occupancy,
       "no candidate elsewhere"},
      {"a half turn lands more, but as much in space the target saw empty",
       {landing(0, 0, 3.1, 20, {80, 85, 82}, 100, 30), landing(0, 0, 0, 20, {60, 62, 61})},
       {},
       0.1,
       1,
       On::occupancy,
       ""},
      {"finer than 0.1 m: the place on pooled cells, the pose at it that lands the most on its own",
       {pooledAs(landing(0.1, 0, 0, 40, {40, 45}), landing(0.1, 0, 0, 20, {70, 75})),
        pooledAs(landing(0, 0, 0, 40, {60, 65}), landing(0, 0, 0, 20, {68, 74})),
        pooledAs(landing(5, 0, 0, 40, {20, 25}), landing(5, 0, 0, 20, {30, 35}))},
       {},
       0.05,
       1,
       On::occupancy,
       ""},
      // 3. Corroborated: a dense search's clear best pose and a feature estimate at the occupancy's best place.
      {"corroborated",
       {as(right(), From::search_wide, 0, one_vote), as(along(), From::search_pooled)},
       {wideAtRight()},
       0.1,
       0,
       On::corroborated,
       ""},
      {"the search's best within chance of its next (1.04x)",
       {as(right(), From::search_wide, 0, one_vote), as(along(), From::search_pooled)},
       {searchLead(From::search_wide, 0, 0, 0, 600, 600 / 1.04)},
       0.1,
       -1,
       On::occupancy,
       "search_wide's best pose is at its place but within chance of its next or a candidate elsewhere (1.04x, "
       "0.7 sigma)"},
      {"the search's best ahead of its own next, not of a candidate elsewhere judged as it judges its poses",
       {as(right(), From::search_wide, 0, one_vote), scoring(as(along(), From::features), 560)},
       {wideAtRight()},
       0.1,
       -1,
       On::occupancy,
       "search_wide's best pose is at its place but within chance of its next or a candidate elsewhere (1.07x, "
       "1.2 sigma)"},
      {"24 % of its telling cells in the target's empty space (at most 20 %)",
       {contradicting(as(right(), From::search_wide, 0, one_vote), 240), as(along(), From::search_pooled)},
       {wideAtRight()},
       0.1,
       -1,
       On::occupancy,
       "it lands 24 % as many telling cells in space the other map saw empty"},
      {"no feature estimate agrees with it",
       {as(right(), From::search_wide), as(along(), From::search_pooled)},
       {wideAtRight()},
       0.1,
       -1,
       On::occupancy,
       "no slice-pair estimate of the features agrees with it"},
      {"the search's own best is the copy, this its runner-up",
       {as(right(), From::search_wide, 1, one_vote), as(along(), From::search_wide)},
       {wideAtRight()},
       0.1,
       -1,
       On::occupancy,
       "no dense search's best pose is at its place"},
      {"the features alone corroborate nothing",
       {as(right(), From::features, 0, one_vote), as(along(), From::feature_rival, 1)},
       {wideAtRight()},
       0.1,
       -1,
       On::occupancy,
       "no dense search of the occupancy"},
      // 4. The votes: the candidate most slice-pair estimates agree with, source slice by source slice.
      {"a street's poses along its facades land alike; the votes tell them apart",
       {as(landing(3, 0, 0, 20, {60, 50, 70}), From::features, 0, streetVotes(false)),
        as(landing(0, 0, 0, 20, {55, 65, 58}), From::feature_rival, 1, streetVotes(true))},
       {},
       0.1,
       1,
       On::feature_votes,
       ""},
      {"nothing lands (slices sent as features): the votes alone, against none elsewhere",
       {as(landing(0, 0, 0, 0, {0}), From::features, 0, std::vector<int>(12, 2))},
       {},
       0.1,
       0,
       On::feature_votes,
       ""},
      {"votes on 2 source slices are no lead",
       {as(landing(0, 0, 0, 0, {0}), From::features, 0, {5, 5})},
       {},
       0.1,
       -1,
       On::occupancy,
       "leads no votes elsewhere (no candidate is) by 1.4 sigma over 2 source slices"},
      // 5. The second look: a search's clear best pose at the place, found again with the maps' roles swapped.
      {"a clear best pose at the place, not yet looked at again",
       {right(), along()},
       {searchLead(From::search_at_grid, 0.05, 0, 0, 900, 300)},
       0.1,
       -1,
       On::occupancy,
       "",
       From::search_at_grid},
      {"found again", {right(), along()}, {gridFoundAgain()}, 0.1, 0, On::second_look, ""},
      {"found elsewhere with the maps' roles swapped",
       {right(), along()},
       {searchLead(From::search_at_grid, 0, 0, 0, 900, 300, SecondLook{true, false, 2.4})},
       0.1,
       -1,
       On::occupancy,
       "search_at_grid with the maps' roles swapped found another place, 2.40 m apart"},
      {"1.3x ahead of its next is not clear",
       {right(), along()},
       {searchLead(From::search_at_grid, 0, 0, 0, 900, 900 / 1.3, SecondLook{true, true, 0.0})},
       0.1,
       -1,
       On::occupancy,
       ""},
      {"clear, but over fewer slices than min_support: a floor alone",
       {right(), along()},
       {[] {
         SearchLead thin = gridFoundAgain();
         thin.found.best.support = MatchParams{}.min_support - 1;
         return thin;
       }()},
       0.1,
       -1,
       On::occupancy,
       ""},
      {"another search's clear best pose elsewhere",
       {right(), along()},
       {gridFoundAgain(), searchLead(From::search_wide, 3, 1, 1.5, 500, 200)},
       0.1,
       -1,
       On::occupancy,
       "search_wide's best pose lies elsewhere, 2.50x ahead of its next"},
      {"the pose found again, not another at its place that lands a little more",
       {as(landing(0.3, 0, 0, 6, {63, 54, 71}), From::search_pooled, 1), as(right(), From::search_at_grid),
        as(landing(1.2, 0, 0, 6, {60, 56, 66}), From::search_wide)},
       {gridFoundAgain()},
       0.1,
       1,
       On::second_look,
       ""},
  };
}

}  // namespace

// The decision, row by row: each way it answers (steps 3-5 of
// docs/algorithm.md, "One decision") and each way one falls short, with the
// reason it gives.
TEST(CandidateDecision, TruthTable) {
  for (const Row& row : truthTable()) {
    SCOPED_TRACE(row.what);
    const CandidateVerdict v = decide(row.candidates, row.searches, row.grid);
    EXPECT_EQ(v.answer, row.answer) << v.reason;
    if (row.answer >= 0) {
      EXPECT_EQ(v.on, row.on);
      EXPECT_TRUE(v.reason.empty()) << v.reason;
    } else {
      EXPECT_FALSE(v.reason.empty() && !v.needs_look);
      EXPECT_NE(v.reason.find(row.reason), std::string::npos) << v.reason;
    }
    EXPECT_EQ(v.needs_look, row.needs_look);
  }
}

TEST(CandidateDecision, AnAnswerSaysHowClearItIsAndOverHowManySlices) {
  const std::vector<Row> table = truthTable();
  const CandidateVerdict occupancy = decide(table[0].candidates, {}, 0.1);
  EXPECT_GE(occupancy.lead_sigma, kBars.significant);
  EXPECT_EQ(occupancy.slices, 20);
  const CandidateVerdict corroborated = decide(table[5].candidates, table[5].searches, 0.1);
  ASSERT_EQ(corroborated.on, On::corroborated);
  EXPECT_LT(corroborated.lead_sigma, kBars.significant) << "the occupancy alone does not tell them apart";
  const CandidateVerdict second_look = decide({right(), along()}, {gridFoundAgain()}, 0.1);
  ASSERT_EQ(second_look.on, On::second_look);
  EXPECT_NEAR(second_look.lead_sigma, 600 / std::sqrt(1200.0), 1e-9) << "the search's lead over its next";
  const CandidateVerdict pooled = decide(table[4].candidates, {}, 0.05);
  EXPECT_EQ(pooled.slices, 20) << "the place's lead, on the pooled slices";
  const CandidateVerdict none = decide({}, {}, 0.1);
  EXPECT_EQ(none.answer, -1);
  EXPECT_EQ(none.reason, "no candidate pose");
}
