// Success rate on generated worlds at the paper's two noise levels: half-length
// worlds by default (the same buildings and streets, half the matching work),
// the full-size ones under the `large` label.
#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "core/matcher.hpp"
#include "synth/synth.hpp"

using namespace tomomap;
using namespace tomomap::synth;

struct WorldCase {
  WorldType type;
  const char* noise;
  double scale = 1.0;  ///< world length factor (synth --scale)
  /// The first seed matched here: seeds below it are matched elsewhere (the
  /// regression matrix's own worlds), and count as right here.
  uint64_t first_seed = 1;
};

void PrintTo(const WorldCase& c, std::ostream* os) { *os << toString(c.type) << "/" << c.noise << " x" << c.scale; }

class SynthAccuracy : public ::testing::TestWithParam<WorldCase> {};

TEST_P(SynthAccuracy, AtLeastNineOfTenSeedsSucceed) {
  const WorldCase wc = GetParam();
  int successes = static_cast<int>(wc.first_seed) - 1;
  for (uint64_t seed = wc.first_seed; seed <= 10; ++seed) {
    SceneParams sp;
    sp.type = wc.type;
    sp.seed = seed;
    sp.scale = wc.scale;
    const Scene scene = makeScene(sp);
    const auto maps = scanScene(scene, noiseLevel(wc.noise), seed);
    MatchParams mp;
    mp.grid = scene.grid;
    const MatchResult r = matchMaps(maps[0].points, maps[1].points, mp);
    const Pose4 truth = Pose4::fromMatrix(maps[0].pose * maps[1].pose.inverse());
    const PoseError e = poseError(r.T_target_source, truth);
    // The paper's rule: translation below 5 grid cells and yaw below 10 degrees.
    const bool ok = r.reliable && e.translation < 5 * scene.grid && e.yaw < radians(10);
    successes += ok;
    std::cout << toString(wc.type) << " " << wc.noise << " seed " << seed << ": "
              << (r.reliable ? "" : "no reliable match, ") << "translation error " << e.translation << " m, yaw error "
              << e.yaw << " rad, " << r.timings.total() << " s" << (ok ? "" : "  FAILED") << "\n";
  }
  EXPECT_GE(successes, 9);
}

std::string caseName(const ::testing::TestParamInfo<WorldCase>& p) {
  return toString(p.param.type) + "_" + p.param.noise;
}

// Half length: seeds 1-5 of each are the regression matrix's own worlds at
// the same grid (tests/suites/matrix.toml: indoor x0.5 at g 0.05, outdoor
// x0.5 at g 0.2, both noises), where RegressionMatrix asserts every one right
// (their families' floor is all 10); matched here again they would only
// repeat it. Here seeds 6-10: at least 4 of 5, so at least 9 of 10 in all.
// The matrix judges by eval's error over the source's points, this test by
// the error at the origin and in yaw: on those 20 pairs both put every
// answer within 2.1 cells and 1 degree (2026-11-30), the bar 5 cells and 10.
INSTANTIATE_TEST_SUITE_P(Worlds, SynthAccuracy,
                         ::testing::Values(WorldCase{WorldType::Indoor, "low", 0.5, 6},
                                           WorldCase{WorldType::Indoor, "high", 0.5, 6},
                                           WorldCase{WorldType::Outdoor, "low", 0.5, 6},
                                           WorldCase{WorldType::Outdoor, "high", 0.5, 6}),
                         caseName);

INSTANTIATE_TEST_SUITE_P(LargeWorlds, SynthAccuracy,
                         ::testing::Values(WorldCase{WorldType::Indoor, "low"}, WorldCase{WorldType::Indoor, "high"},
                                           WorldCase{WorldType::Outdoor, "low"}, WorldCase{WorldType::Outdoor, "high"}),
                         caseName);

/// One pair of a generated world matched at `grid`, and how far it is off.
struct RoomMatch {
  MatchResult result;
  PoseError error;
  /// The paper's rule, as for the tall worlds above.
  bool right(double grid) const { return error.translation < 5 * grid && error.yaw < radians(10); }
  bool answeredWrong(double grid) const { return result.reliable && !right(grid); }
};

/// One pair of a generated world of `type`, matched at `grid`.
RoomMatch matchWorld(WorldType type, uint64_t seed, const char* noise, double grid) {
  SceneParams sp;
  sp.type = type;
  sp.seed = seed;
  const auto maps = scanScene(makeScene(sp), noiseLevel(noise), seed);
  MatchParams mp;
  mp.grid = grid;
  RoomMatch m;
  m.result = matchMaps(maps[0].points, maps[1].points, mp);
  m.error = poseError(m.result.T_target_source, Pose4::fromMatrix(maps[0].pose * maps[1].pose.inverse()));
  return m;
}

/// A room pair of `synth -w room`.
RoomMatch matchRoom(uint64_t seed, const char* noise, double grid) {
  return matchWorld(WorldType::Room, seed, noise, grid);
}

std::string wrongAnswer(const RoomMatch& m) {
  std::ostringstream out;
  out << "answered wrong: " << m.error.translation << " m, " << m.error.yaw << " rad off (by "
      << fromName(m.result.answered_by) << ", features " << m.result.features.support << " vs "
      << m.result.features.runner_up_support << ", dense lead " << m.result.dense.at_grid_lead << ")";
  return out.str();
}

/// Whether any dense search ran and found a pose.
bool searchedDensely(const MatchResult& r) {
  return r.dense.at_grid_lead > 0 || r.dense.wide_lead > 0 || r.dense.pooled_lead > 0;
}

/// The lead of the dense search that answered (0 for a feature answer).
double answeringLead(const MatchResult& r) {
  switch (r.answered_by) {
    case Candidate::From::search_at_grid:
      return r.dense.at_grid_lead;
    case Candidate::From::search_wide:
      return r.dense.wide_lead;
    case Candidate::From::search_pooled:
      return r.dense.pooled_lead;
    default:
      return 0;
  }
}

/// Which kind of search answered.
enum class By { features, dense_search };

/// Expects `m` answered right at `grid` by `by`; `what` names the pair in the messages.
void expectAnsweredRightBy(const RoomMatch& m, double grid, By by, const std::string& what) {
  EXPECT_TRUE(m.result.reliable && m.right(grid)) << what << ": " << m.result.reason << " " << m.error.translation
                                                  << " m off (by " << fromName(m.result.answered_by) << ")";
  EXPECT_EQ(m.result.answered_by == Candidate::From::features ? By::features : By::dense_search, by)
      << what << ": by " << fromName(m.result.answered_by);
}

// Small rooms (under 32 slices at g 0.1, partial overlap), seeds 1-10 at low
// and high noise, g 0.1 and 0.05: the features alone refused all ten
// (docs/results.md, "Small rooms"); the dense search answers them. How many
// are right, and that none is wrong, is the regression matrix's gate
// (tests/suites/matrix.toml, families "room g0.05" and "room g0.1"), which
// matches the same pairs; the tests below keep the cases that shaped it.

// A half-turned room fits a room's walls as well as the right pose, and with
// high noise the furniture's cells landed on each other nearly as often too:
// seeds 2, 3 and 6 at g 0.1 were refused, the search's best pose leading by
// 1.19-1.36x in telling cells. Under the half turn each map's furniture lands
// in the other's open floor space; counted against the pose, the right one
// now leads by 1.66-2.81x and answers alone (docs/algorithm.md, "Empty space").
TEST(SmallRooms, EmptySpaceTheOtherMapSawTellsARoomFromItsHalfTurn) {
  int looked_again = 0;
  for (const uint64_t seed : {2, 3, 6}) {
    const RoomMatch m = matchRoom(seed, "high", 0.1);
    expectAnsweredRightBy(m, 0.1, By::dense_search, "seed " + std::to_string(seed));
    EXPECT_GE(answeringLead(m.result), 1.4) << "seed " << seed;
    EXPECT_EQ(m.result.dense.pooled_lead, 0.0) << "seed " << seed << ": not the grid's search alone";
    // The grid's search answering alone had a second look, the maps' roles
    // swapped, and it put the source's origin within two looks' tolerance
    // (sqrt(2) x 5 cells); the wide search's answer (seed 3) had the features'.
    if (!m.result.dense.second_look_apart) continue;
    ++looked_again;
    EXPECT_LE(*m.result.dense.second_look_apart, std::sqrt(2.0) * 5 * 0.1) << "seed " << seed;
  }
  EXPECT_GE(looked_again, 1) << "no answer had a second look";
}

// The right pose need not be among the search's candidates: on a held-out
// room (seed 208, high noise, g 0.1) none of its 12 was, and the best, one
// enclosure laid on a like one 2.75 m off, led its next by 1.40x once empty
// space was read. It landed 24 % as many telling cells in space the other map
// saw empty as on its occupancy; right best poses landed at most 18 %. The
// decision over the candidates would corroborate it (a dense search's best
// pose, a feature estimate), but not a pose the empty space contradicts so.
TEST(SmallRooms, APoseThatContradictsWhatTheOtherMapSawEmptyDoesNotAnswer) {
  const RoomMatch m = matchRoom(208, "high", 0.1);
  EXPECT_FALSE(m.result.reliable) << wrongAnswer(m);
  EXPECT_NE(m.result.reason.find("in space the other map saw empty"), std::string::npos) << m.result.reason;
}

// A noise-free room at g 0.05 (seed 8) came out of the features reliable and
// half-turned: 7 slice pairs against 3, a lead of more than 2x, which then
// skipped the dense check. A weak winner is checked however far it leads.
TEST(SmallRooms, AWeakFeatureWinnerIsCheckedDenselyHoweverFarItLeads) {
  const RoomMatch m = matchRoom(8, "none", 0.05);
  EXPECT_TRUE(searchedDensely(m.result)) << "the dense search did not run";
  EXPECT_FALSE(m.answeredWrong(0.05)) << wrongAnswer(m);
}

// A high-noise room at g 0.05 (seed 14) came out of the features reliable and
// half-turned (9 slice pairs against 5) while the dense search preferred the
// right pose by 1.35x, short of the 1.4x it needs to answer. Refusing needs
// less than answering: that lead is enough to refuse the features (the search
// on pooled occupancy now answers it, right).
TEST(SmallRooms, ADenseSearchShortOfAnsweringStillRefusesAFeatureAnswerItContradicts) {
  const RoomMatch m = matchRoom(14, "high", 0.05);
  EXPECT_FALSE(m.answeredWrong(0.05)) << wrongAnswer(m);
}

// Of 820 room pairs (seeds 1-200 at low and high noise, 1-10 noise-free; g 0.1
// and 0.05) the features answered 33, 10 of them wrong, 9 of those with high
// noise at g 0.05: half-turned, or one enclosure laid on a similar one. The
// dense search's best pose was another one (seeds 112, 177), or the same one
// but too close to its next to tell (93, 108: 1.02-1.04x); seed 11 led 15
// slice pairs to 5, and so skipped the dense search before. An answer the
// dense search does not confirm is refused; one it confirms (seed 122, 1.70x)
// stands.
TEST(SmallRooms, AFeatureAnswerTheDenseSearchDoesNotConfirmIsRefused) {
  for (const uint64_t seed : {11, 93, 108, 112, 177}) {
    const RoomMatch m = matchRoom(seed, "high", 0.05);
    EXPECT_TRUE(searchedDensely(m.result)) << "seed " << seed << ": the dense search did not run";
    EXPECT_FALSE(m.answeredWrong(0.05)) << "seed " << seed << " " << wrongAnswer(m);
  }
  const RoomMatch confirmed = matchRoom(122, "high", 0.05);
  expectAnsweredRightBy(confirmed, 0.05, By::features, "seed 122");
}

// A narrow feature winner for a half-turned room is not the answer. Seed 150
// at high noise, g 0.1: the features led 8 to 2 for it (refused before the
// dense search), the dense search 1.94x for the right pose (21x since it reads
// empty space) and replaced it; now the half-turned room's landing loses to
// the right pose's among the features' own answers. The rule that a clear
// dense pose replaces a feature answer stays (Verdict.*).
TEST(SmallRooms, ANarrowFeatureWinnerForAHalfTurnedRoomIsNotTheAnswer) {
  const RoomMatch m = matchRoom(150, "high", 0.1);
  EXPECT_TRUE(m.result.reliable && m.right(0.1))
      << m.result.reason << " " << m.error.translation << " m off (by " << fromName(m.result.answered_by) << ")";
}

// At g 0.05 a room's 5 cm of wall noise splits its walls across neighbouring
// cells, and the dense search at the map's grid leaves more rooms refused
// than at g 0.1 (of 200 low-noise seeds, 49 refused at 0.05 were right at
// 0.1). Where it does, the search is asked again on the occupancy pooled to
// 0.1 m: seed 3 at low noise and seed 10 at high noise were refused before,
// each short of a clear pose at 0.05 m cells (docs/results.md, "Small rooms").
TEST(SmallRooms, WhereTheGridLeavesARoomRefusedPooledOccupancyAnswersIt) {
  for (const auto& [seed, noise] : {std::pair<uint64_t, const char*>{3, "low"}, {10, "high"}}) {
    const RoomMatch m = matchRoom(seed, noise, 0.05);
    expectAnsweredRightBy(m, 0.05, By::dense_search, "seed " + std::to_string(seed) + " " + noise);
    EXPECT_EQ(m.result.answered_by, Candidate::From::search_pooled)
        << "seed " << seed << ": not the pooled search's answer";
  }
}

// Two searches, neither sure enough alone, answer where they agree. Seed 23
// at low noise, g 0.05: the features found the right pose on too few slice
// pairs, and the search on a raster twice as fine lands on it 1.25x ahead of
// its next (a thin answer checked wide, verdict.hpp). Before that check the
// map's grid and pooled occupancy agreed on it (1.24x at 0.05 m cells, 1.37x
// at 0.1 m); the truth table keeps that rule's rows. Seed 11 at low noise,
// g 0.1, has both searches on one wrong pose, at 1.11x and 1.02x: refused.
TEST(SmallRooms, TwoSearchesShortOfAnsweringAnswerWhereTheyAgree) {
  const RoomMatch agreed = matchRoom(23, "low", 0.05);
  expectAnsweredRightBy(agreed, 0.05, By::dense_search, "seed 23");
  EXPECT_GE(agreed.result.dense.wide_lead, 1.2) << "the wide search confirmed it";
  EXPECT_LT(agreed.result.dense.wide_lead, 1.4) << "a lead that would answer alone";
  const RoomMatch m = matchRoom(11, "low", 0.1);
  EXPECT_FALSE(m.result.reliable) << wrongAnswer(m);
}

// A search on pooled occupancy does not confirm a feature answer: on a
// held-out room (seed 203, high noise, g 0.05) the features answered 0.27 m
// off in height, within the 5-slice smear a confirmation allows, and the
// pooled search confirmed it (1.28x) into a reliable answer 0.29 m off.
TEST(SmallRooms, APooledSearchDoesNotConfirmAFeatureAnswer) {
  const RoomMatch m = matchRoom(203, "high", 0.05);
  EXPECT_FALSE(m.answeredWrong(0.05)) << wrongAnswer(m);
}

// A small map's answer takes the height offset where most of the source's
// occupancy lands on the target's: the features' offset is the centre of a
// smear of offsets. Seed 159 at high noise, g 0.05, is a feature answer the
// dense search confirms; at the features' offset, two slices low, it would be
// 0.150 m off (0.140 m of it in height), at the occupancy's 0.067 m. (Seed
// 111, which showed it first, is answered by the pooled search since a
// search's poses are refined on fewer cells, as right.)
TEST(SmallRooms, AnAnswerTakesTheHeightWhereTheOccupancyMeetsBest) {
  const RoomMatch m = matchRoom(159, "high", 0.05);
  expectAnsweredRightBy(m, 0.05, By::features, "seed 159");
  EXPECT_LT(m.error.translation, 0.1) << "yaw error " << m.error.yaw;
}

// The full-size building at g 0.2 has 31 slices a map, so the small-map rules
// apply. Its dense search, on a raster coarsened for maps this large, finds no
// pose that holds: its best poses land 53-73 % as many telling cells in space
// the other map saw empty as on occupancy (seeds 1-5). The features' pose is
// then judged by its own landing: on seeds 1 and 4 (16 vs 2 and 15 vs 7 slice
// pairs) it contradicts 1.8 and 2.6 % and stands, right; on seeds 3 and 5 the
// features' answer is 8.8 and 8.7 m along the building and contradicts 66 and
// 90 %: still refused. All five were refused before.
TEST(SmallMaps, AFeatureAnswerWhosePoseHoldsStandsWhereTheDenseSearchFoundNone) {
  for (const uint64_t seed : {1, 4}) {
    const RoomMatch m = matchWorld(WorldType::Indoor, seed, "low", 0.2);
    expectAnsweredRightBy(m, 0.2, By::features, "building seed " + std::to_string(seed));
  }
}

TEST(SmallMaps, ACopyOneRoomAlongLosesToTheRightPoseOnTheOccupancy) {
  // The full-size building at g 0.2: slice pairs supported a copy of the pose
  // one room (8.7 m) along as much as the right pose or more (seed 2 tied 4
  // to 4, seeds 3 and 5 won by the copy); landed on the occupancy, the copy
  // runs into space the other map saw empty.
  for (const uint64_t seed : {2, 3, 5}) {
    const RoomMatch m = matchWorld(WorldType::Indoor, seed, "low", 0.2);
    expectAnsweredRightBy(m, 0.2, By::features, "building seed " + std::to_string(seed));
  }
}
