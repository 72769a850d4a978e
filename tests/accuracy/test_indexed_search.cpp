// The indexed search (offset_search.hpp) against the exhaustive one it
// replaces: on every case the accuracy tests use, the same verdict, the same
// winning height offset and the same transform, from a fraction of the pairs.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "core/matcher.hpp"
#include "support.hpp"
#include "synth/synth.hpp"

using namespace tomomap;
using namespace tomomap::synth;

namespace {

/// Pairs matched by both searches over the cases of one test.
struct Tally {
  size_t indexed = 0, exhaustive = 0, cases = 0;
  ~Tally() {
    if (cases)
      std::cout << cases << " cases: the indexed search matched " << indexed << " of " << exhaustive << " slice pairs ("
                << 100.0 * static_cast<double>(indexed) / static_cast<double>(exhaustive) << " %)\n";
  }
};

void expectSameAnswer(const MapFeatures& target, const MapFeatures& source, MatchParams params, const std::string& what,
                      Tally& tally) {
  params.exhaustive = true;
  const MatchResult all = matchFeatures(target, source, params);
  params.exhaustive = false;
  const MatchResult indexed = matchFeatures(target, source, params);
  tally.indexed += indexed.features.slice_pairs;
  tally.exhaustive += all.features.slice_pairs;
  ++tally.cases;
  ASSERT_EQ(indexed.reliable, all.reliable)
      << what << ": indexed '" << indexed.reason << "', exhaustive '" << all.reason << "'";
  EXPECT_EQ(indexed.answered_by, all.answered_by) << what;
  if (!all.reliable) return;
  if (indexed.height_offset != all.height_offset)
    std::cout << what << ": indexed offset " << indexed.height_offset << " support " << indexed.features.support
              << " (runner-up " << indexed.features.runner_up_support << " at " << indexed.features.runner_up_offset
              << "), exhaustive offset " << all.height_offset << " support " << all.features.support << " (runner-up "
              << all.features.runner_up_support << " at " << all.features.runner_up_offset << ")\n";
  EXPECT_EQ(indexed.height_offset, all.height_offset) << what;
  EXPECT_EQ(indexed.features.support, all.features.support) << what;
  const PoseError e = poseError(indexed.T_target_source, all.T_target_source);
  EXPECT_LT(e.translation, 0.001) << what;
  EXPECT_LT(e.yaw, 0.0005) << what;
}

/// The moves of DemoRoom.SucceedsWhereverTheSourceIsMoved: its four corners, then 24 drawn at random.
std::vector<Pose4> demoRoomMoves() {
  std::vector<Pose4> moves{
      {50, 50, 3, kPi}, {-50, -50, -3, -kPi + 1e-6}, {50, -50, -3, kPi / 2}, {-50, 50, 3, -kPi / 2}};
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 24; ++i) moves.push_back({50 * u(rng), 50 * u(rng), 3 * u(rng), kPi * u(rng)});
  return moves;
}

/// Both directions of the demo-room pair, then the source moved by moves [first, last).
void expectDemoRoomAnswersAlike(size_t first, size_t last, bool both_directions) {
  const auto d = test::loadDemoPair();
  const MatchParams p;
  const MapFeatures f1 = describeMap(d.map1, p), f2 = describeMap(d.map2, p);
  Tally tally;
  if (both_directions) {
    expectSameAnswer(f1, f2, p, "pcd2 -> pcd1", tally);
    expectSameAnswer(f2, f1, p, "pcd1 -> pcd2", tally);
  }
  const std::vector<Pose4> moves = demoRoomMoves();
  for (size_t i = first; i < std::min(last, moves.size()); ++i) {
    const Pose4& M = moves[i];
    expectSameAnswer(f1, describeMap(transformPoints(d.map2, M), p), p,
                     "move " + std::to_string(M.x) + " " + std::to_string(M.y) + " " + std::to_string(M.yaw), tally);
  }
}

/// Every world type and noise level, seeds [first, last].
void expectGeneratedWorldsAnswerAlike(uint64_t first, uint64_t last) {
  Tally tally;
  for (WorldType type : {WorldType::Indoor, WorldType::Outdoor, WorldType::Room})
    for (const char* noise : {"none", "low", "high"})
      for (uint64_t seed = first; seed <= last; ++seed) {
        SceneParams sp;
        sp.type = type;
        sp.seed = seed;
        sp.scale = type == WorldType::Room ? 1.0 : 0.5;
        const Scene scene = makeScene(sp);
        const auto maps = scanScene(scene, noiseLevel(noise), seed);
        MatchParams p;
        p.grid = type == WorldType::Room ? 0.1 : scene.grid;
        expectSameAnswer(describeMap(maps[0].points, p), describeMap(maps[1].points, p), p,
                         toString(type) + " " + noise + " seed " + std::to_string(seed), tally);
      }
}

// The default run checks the corners and the first two random moves, and
// seed 1 of every world at every noise; the `large` label (LargeIndexedSearch)
// the rest (a match that runs every dense search takes about a second on the
// demo room, twice here).
constexpr size_t kDemoRoomMovesInCi = 6;
constexpr uint64_t kSeedsInCi = 1;

}  // namespace

TEST(IndexedSearch, AnswersTheDemoRoomLikeTheExhaustiveSearchWhereverTheSourceIsMoved) {
  REQUIRE_DEMO_ROOM();
  expectDemoRoomAnswersAlike(0, kDemoRoomMovesInCi, true);
}

TEST(LargeIndexedSearch, AnswersTheDemoRoomLikeTheExhaustiveSearchWhereverTheSourceIsMoved) {
  REQUIRE_DEMO_ROOM();
  expectDemoRoomAnswersAlike(kDemoRoomMovesInCi, demoRoomMoves().size(), false);
}

TEST(IndexedSearch, RefusesTwoIdenticalFloorsLikeTheExhaustiveSearch) {
  REQUIRE_DEMO_ROOM();
  const auto d = test::loadDemoPair();
  Points two_floors = d.map1;
  for (const auto& q : d.map1) two_floors.push_back(q + Eigen::Vector3f(0, 0, 4.0f));
  const MatchParams p;
  MatchParams indexed = p;
  const MatchResult r = matchMaps(two_floors, d.map2, indexed);
  EXPECT_FALSE(r.reliable);
  // The other floor's copy of the right pose lands as much: no candidate is clear of it.
  EXPECT_NE(r.reason.find("leads the best elsewhere by"), std::string::npos) << r.reason;
  Tally tally;
  expectSameAnswer(describeMap(two_floors, p), describeMap(d.map2, p), p, "two floors", tally);
}

TEST(IndexedSearch, AnswersGeneratedWorldsLikeTheExhaustiveSearch) { expectGeneratedWorldsAnswerAlike(1, kSeedsInCi); }

TEST(LargeIndexedSearch, AnswersGeneratedWorldsLikeTheExhaustiveSearch) {
  expectGeneratedWorldsAnswerAlike(kSeedsInCi + 1, 10);
}
