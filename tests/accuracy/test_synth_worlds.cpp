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

/// Expects `m` answered right at `grid`; `what` names the pair in the messages.
void expectAnsweredRight(const RoomMatch& m, double grid, const std::string& what) {
  EXPECT_TRUE(m.result.reliable && m.right(grid)) << what << ": " << m.result.reason << " " << m.error.translation
                                                  << " m off (by " << fromName(m.result.answered_by) << ")";
}

// Small rooms (under 32 slices at g 0.1, partial overlap), seeds 1-10 at low
// and high noise, g 0.1 and 0.05: the features alone refused all ten
// (docs/results.md, "Small rooms"); the dense searches' poses, as candidates,
// answer them. How many are right, and that none is wrong, is the regression
// matrix's gate (tests/suites/matrix.toml, families "room g0.05" and "room
// g0.1"), which matches the same pairs; the tests below keep the cases that
// shaped the rules the one decision replaced, each as a user would check it:
// answered right, or refused, never wrong. Those among the matrix's pairs are
// gated there alone: rooms seeds 1-10 (a half turn told by the empty space
// the other map saw, seeds 2, 3 and 6 high at g 0.1; the pooled and wide
// searches where the grid's leaves a room unclear, seeds 3 low and 10 high at
// g 0.05) and the full-size building at g 0.2 (a copy one room along losing
// to the right pose on the occupancy, seeds 2, 3 and 5), family "indoor g0.2".

// The right pose need not be among the candidates: on a held-out room (seed
// 208, high noise, g 0.1) none of the dense search's was, and the best, one
// enclosure laid on a like one 2.75 m off, led its next by 1.40x once empty
// space was read. It landed 24 % as many telling cells in space the other map
// saw empty as on its occupancy; right best poses landed at most 18 %. A
// dense search's best pose and a feature estimate corroborate it, but not a
// pose the empty space contradicts so (DecisionBars::most_contradicted).
TEST(SmallRooms, APoseThatContradictsWhatTheOtherMapSawEmptyDoesNotAnswer) {
  const RoomMatch m = matchRoom(208, "high", 0.1);
  EXPECT_FALSE(m.result.reliable) << wrongAnswer(m);
  EXPECT_NE(m.result.reason.find("in space the other map saw empty"), std::string::npos) << m.result.reason;
}

// A noise-free room at g 0.05 (seed 8) came out of the features reliable and
// half-turned: 7 slice pairs against 3. However far the features lead, their
// answer is one candidate among the dense searches' poses.
TEST(SmallRooms, AFeatureWinnerIsOneCandidateHoweverFarItLeads) {
  const RoomMatch m = matchRoom(8, "none", 0.05);
  EXPECT_TRUE(searchedDensely(m.result)) << "the dense search did not run";
  EXPECT_FALSE(m.answeredWrong(0.05)) << wrongAnswer(m);
}

// Of 820 room pairs (seeds 1-200 at low and high noise, 1-10 noise-free; g 0.1
// and 0.05) the features answered 33, 10 of them wrong, 9 of those with high
// noise at g 0.05: half-turned, or one enclosure laid on a similar one. The
// dense search's best pose was another one (seeds 112, 177), or the same one
// but too close to its next to tell (93, 108: 1.02-1.04x); seed 11 led 15
// slice pairs to 5. None of them is answered wrong; seed 122, which the
// dense search confirmed (1.70x), is answered right.
TEST(SmallRooms, AFeatureAnswerTheOccupancyDoesNotBearOutIsNotTheAnswer) {
  for (const uint64_t seed : {11, 93, 108, 112, 177}) {
    const RoomMatch m = matchRoom(seed, "high", 0.05);
    EXPECT_TRUE(searchedDensely(m.result)) << "seed " << seed << ": the dense search did not run";
    EXPECT_FALSE(m.answeredWrong(0.05)) << "seed " << seed << " " << wrongAnswer(m);
  }
  expectAnsweredRight(matchRoom(122, "high", 0.05), 0.05, "seed 122");
}

// A narrow feature winner for a half-turned room is not the answer. Seed 150
// at high noise, g 0.1: the features led 8 to 2 for it; the right pose, a
// dense search's best, lands far more on the occupancy.
TEST(SmallRooms, ANarrowFeatureWinnerForAHalfTurnedRoomIsNotTheAnswer) {
  expectAnsweredRight(matchRoom(150, "high", 0.1), 0.1, "seed 150");
}

// Searches each short of a clear best pose. Seed 23 at low noise, g 0.05: the
// features found the right pose on too few slice pairs, and the wide search
// lands on it 1.25x ahead of its next. Seed 11 at low noise, g 0.1, was
// refused while its grid and pooled searches' best poses, 1.11x and 1.02x
// ahead, lay elsewhere; the candidates hold the right pose, and it answers.
TEST(SmallRooms, SearchesShortOfAClearBestPoseStillProposeTheRightOne) {
  expectAnsweredRight(matchRoom(23, "low", 0.05), 0.05, "seed 23");
  expectAnsweredRight(matchRoom(11, "low", 0.1), 0.1, "seed 11");
}

// A held-out room (seed 203, high noise, g 0.05): the features answered
// 0.27 m off in height, and a search on pooled occupancy once found the same
// place (1.28x) and made it a reliable answer 0.29 m off. It is answered
// right or refused, not wrong.
TEST(SmallRooms, AFeatureAnswerOffInHeightIsNotAnsweredRight) {
  const RoomMatch m = matchRoom(203, "high", 0.05);
  EXPECT_FALSE(m.answeredWrong(0.05)) << wrongAnswer(m);
}

// Every candidate takes the height offset where most of the source's
// occupancy lands on the target's: the features' offset is the centre of a
// smear of offsets. Seed 159 at high noise, g 0.05: at the features' offset,
// two slices low, the answer was 0.150 m off (0.140 m of it in height); at
// the occupancy's, under 0.1 m.
TEST(SmallRooms, AnAnswerTakesTheHeightWhereTheOccupancyMeetsBest) {
  const RoomMatch m = matchRoom(159, "high", 0.05);
  expectAnsweredRight(m, 0.05, "seed 159");
  EXPECT_LT(m.error.translation, 0.1) << "yaw error " << m.error.yaw;
}
