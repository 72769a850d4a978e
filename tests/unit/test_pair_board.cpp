// Who computes which pair, replayed without a network: claims that race, a
// claimer that disappears, maps that change while a pair is computed. The time
// is injected; nothing sleeps.
#include <gtest/gtest.h>

#include "pair_board.hpp"

using namespace tomomap;
using namespace tomomap::daemon;
using namespace std::chrono_literals;

namespace {

const PairKey kAB{"alpha", "bravo"};

BoardTimings timings() {
  BoardTimings t;
  t.claim_timeout = 8s;
  t.claim_settle = 500ms;
  return t;
}

/// A board of `me` that holds the maps of alpha (version 1) and bravo (version 2).
PairBoard holdingBoth(const std::string& me) {
  PairBoard b(me, timings());
  for (const auto& [id, v] : {std::pair<std::string, uint64_t>{"alpha", 1}, {"bravo", 2}}) {
    if (id == me) {
      b.ownMap(v);
    } else {
      b.mapAnnounced(id, v);
      b.mapHeld(id);
    }
  }
  return b;
}

AgreedTransform resultOf(const PairAt& at, const std::string& by, double x = 1.0) {
  AgreedTransform t;
  t.target = at.pair.first;
  t.source = at.pair.second;
  t.target_version = at.target_version;
  t.source_version = at.source_version;
  t.reliable = true;
  t.T_target_source = {x, 2, 0, 0.5};
  t.computed_by = by;
  return t;
}

const Clock::time_point t0{};

}  // namespace

TEST(PairBoard, WaitsForBothMapsThenClaimsSettlesAndComputes) {
  PairBoard b("alpha", timings());
  b.ownMap(1);
  b.mapAnnounced("bravo", 2);
  EXPECT_EQ(b.status(kAB, t0).state, PairState::WaitingForMaps);
  EXPECT_TRUE(b.step(t0).claims.empty()) << "bravo's map is announced, not held";
  b.mapHeld("bravo");
  EXPECT_EQ(b.status(kAB, t0).state, PairState::Open);

  const BoardStep first = b.step(t0);
  ASSERT_EQ(first.claims.size(), 1u);
  EXPECT_EQ(first.claims[0].pair, kAB);
  EXPECT_EQ(first.claims[0].target_version, 1u);
  EXPECT_EQ(first.claims[0].source_version, 2u);
  EXPECT_FALSE(first.compute);
  EXPECT_EQ(b.status(kAB, t0).state, PairState::Claimed);
  EXPECT_FALSE(b.step(t0 + 499ms).compute) << "competing claims get time to show up";

  const BoardStep go = b.step(t0 + 500ms);
  ASSERT_TRUE(go.compute);
  EXPECT_EQ(go.compute->pair, kAB);
  EXPECT_EQ(b.status(kAB, t0 + 500ms).state, PairState::Computing);
  EXPECT_FALSE(b.step(t0 + 600ms).compute) << "one computation at a time";

  b.computed(resultOf(*go.compute, "alpha"));
  EXPECT_EQ(b.status(kAB, t0 + 1s).state, PairState::Agreed);
  EXPECT_EQ(b.currentResults(), 1u);
  EXPECT_TRUE(b.step(t0 + 2s).claims.empty()) << "nothing left to do";
}

TEST(PairBoard, TwoClaimersTheLowerIdComputesTheOtherYields) {
  PairBoard alpha = holdingBoth("alpha"), bravo = holdingBoth("bravo");
  // Both claim at the same moment and each hears the other's claim.
  const PairAt a = alpha.step(t0).claims.at(0), b = bravo.step(t0).claims.at(0);
  alpha.claimSeen("bravo", b, t0 + 10ms);
  bravo.claimSeen("alpha", a, t0 + 10ms);

  const BoardStep on_alpha = alpha.step(t0 + 500ms), on_bravo = bravo.step(t0 + 500ms);
  ASSERT_TRUE(on_alpha.compute) << "alpha outranks bravo";
  EXPECT_FALSE(on_bravo.compute);
  ASSERT_EQ(on_bravo.yielded.size(), 1u);
  EXPECT_EQ(on_bravo.yielded[0], "alpha<-bravo to alpha");
  EXPECT_EQ(bravo.status(kAB, t0 + 500ms).state, PairState::ClaimedByPeer);
  EXPECT_EQ(bravo.status(kAB, t0 + 500ms).by, "alpha");
  EXPECT_TRUE(bravo.step(t0 + 1s).claims.empty()) << "bravo does not claim again while alpha's claim lives";

  // alpha's result reaches bravo: both store the same.
  const AgreedTransform r = resultOf(*on_alpha.compute, "alpha");
  alpha.computed(r);
  EXPECT_EQ(bravo.estimateSeen(r), PairBoard::Offer::Stored);
  EXPECT_EQ(bravo.status(kAB, t0 + 2s).state, PairState::Agreed);
  EXPECT_EQ(bravo.results().at(kAB).computed_by, "alpha");
}

TEST(PairBoard, AHigherIdClaimDoesNotDisplaceALowerOne) {
  PairBoard charlie("charlie", timings());
  charlie.mapAnnounced("alpha", 1);
  charlie.mapHeld("alpha");
  charlie.mapAnnounced("bravo", 2);
  charlie.mapHeld("bravo");
  charlie.ownMap(3);
  const PairAt at{kAB, 1, 2};
  charlie.claimSeen("alpha", at, t0);
  charlie.claimSeen("bravo", at, t0 + 10ms);
  EXPECT_EQ(charlie.status(kAB, t0 + 20ms).by, "alpha");
  // charlie holds both maps but leaves the pair to alpha.
  for (const PairAt& c : charlie.step(t0 + 20ms).claims) EXPECT_NE(c.pair, kAB);
}

TEST(PairBoard, AClaimerThatDisappearsIsTakenOver) {
  PairBoard bravo = holdingBoth("bravo");
  const PairAt at{kAB, 1, 2};
  bravo.claimSeen("alpha", at, t0);
  EXPECT_TRUE(bravo.step(t0 + 1s).claims.empty());

  // Silence: alpha's claim expires after claim_timeout and bravo takes over.
  const BoardStep later = bravo.step(t0 + 8s + 1ms);
  ASSERT_EQ(later.claims.size(), 1u);
  EXPECT_TRUE(bravo.step(t0 + 8s + 501ms).compute);

  // Or its participant is reported gone: the claim is void at once.
  PairBoard other = holdingBoth("bravo");
  other.claimSeen("alpha", at, t0);
  other.agentGone("alpha");
  EXPECT_EQ(other.step(t0 + 1s).claims.size(), 1u);
}

TEST(PairBoard, ALongComputationRenewsItsClaimSoNobodyTakesOver) {
  PairBoard alpha = holdingBoth("alpha"), bravo = holdingBoth("bravo");
  const PairAt claim = alpha.step(t0).claims.at(0);
  bravo.claimSeen("alpha", claim, t0);
  ASSERT_TRUE(alpha.step(t0 + 500ms).compute);
  // alpha matches for 30 s, far past the 8 s claim timeout, and renews its
  // claim every 2 s; bravo hears each renewal and never claims the pair.
  for (auto t = t0 + 1s; t < t0 + 30s; t += 1s) {
    for (const PairAt& renewed : alpha.step(t).claims) {
      EXPECT_EQ(renewed.pair, kAB);
      bravo.claimSeen("alpha", renewed, t);
    }
    EXPECT_TRUE(bravo.step(t).claims.empty()) << "at " << std::chrono::duration<double>(t - t0).count() << " s";
  }
}

TEST(PairBoard, AClaimForOtherVersionsIsNoClaim) {
  PairBoard bravo = holdingBoth("bravo");
  bravo.claimSeen("alpha", {kAB, 1, 99}, t0);  // alpha holds another version of bravo's map
  EXPECT_EQ(bravo.step(t0 + 1s).claims.size(), 1u);
}

TEST(PairBoard, VersionsChangingMidComputeMakeThePairStaleAndRecomputed) {
  PairBoard alpha = holdingBoth("alpha");
  alpha.step(t0);
  const BoardStep go = alpha.step(t0 + 500ms);
  ASSERT_TRUE(go.compute);
  // bravo's map changes while alpha is matching the old one.
  alpha.mapAnnounced("bravo", 7);
  alpha.computed(resultOf(*go.compute, "alpha"));
  EXPECT_EQ(alpha.status(kAB, t0 + 1s).state, PairState::Stale);
  EXPECT_EQ(alpha.currentResults(), 0u);
  EXPECT_TRUE(alpha.step(t0 + 1s).claims.empty()) << "the new version is not held yet";

  alpha.mapHeld("bravo");
  const BoardStep again = alpha.step(t0 + 2s);
  ASSERT_EQ(again.claims.size(), 1u);
  EXPECT_EQ(again.claims[0].source_version, 7u);
  const BoardStep recompute = alpha.step(t0 + 3s);
  ASSERT_TRUE(recompute.compute);
  EXPECT_EQ(recompute.compute->source_version, 7u);
}

TEST(PairBoard, OurOwnMapChangingVoidsOurClaims) {
  PairBoard alpha = holdingBoth("alpha");
  ASSERT_EQ(alpha.step(t0).claims.size(), 1u);
  alpha.ownMap(5);
  const BoardStep next = alpha.step(t0 + 1s);
  ASSERT_EQ(next.claims.size(), 1u) << "claimed again, for the new version";
  EXPECT_EQ(next.claims[0].target_version, 5u);
  EXPECT_FALSE(next.compute);
}

TEST(PairBoard, DuplicateEstimatesKeepTheHigherRankedComputerOnEveryAgent) {
  const PairAt at{kAB, 1, 2};
  // Two agents computed the same pair (say, a claim was missed); every agent
  // ends with the same one, whatever order the two arrive in.
  for (const bool bravo_first : {true, false}) {
    PairBoard charlie("charlie", timings());
    charlie.mapAnnounced("alpha", 1);
    charlie.mapAnnounced("bravo", 2);
    const AgreedTransform from_a = resultOf(at, "alpha", 1.0), from_b = resultOf(at, "bravo", 1.5);
    if (bravo_first) {
      EXPECT_EQ(charlie.estimateSeen(from_b), PairBoard::Offer::Stored);
      EXPECT_EQ(charlie.estimateSeen(from_a), PairBoard::Offer::Stored);
    } else {
      EXPECT_EQ(charlie.estimateSeen(from_a), PairBoard::Offer::Stored);
      EXPECT_EQ(charlie.estimateSeen(from_b), PairBoard::Offer::Duplicate);
    }
    EXPECT_EQ(charlie.results().at(kAB).computed_by, "alpha");
    EXPECT_EQ(charlie.estimateSeen(from_a), PairBoard::Offer::Duplicate) << "the same result again";
  }
}

TEST(PairBoard, AnEstimateForOldMapsDoesNotReplaceOneForNewer) {
  PairBoard charlie("charlie", timings());
  charlie.mapAnnounced("alpha", 1);
  charlie.mapAnnounced("bravo", 3);
  EXPECT_EQ(charlie.estimateSeen(resultOf({kAB, 1, 3}, "bravo")), PairBoard::Offer::Stored);
  EXPECT_EQ(charlie.estimateSeen(resultOf({kAB, 1, 2}, "alpha")), PairBoard::Offer::Outdated);
  EXPECT_EQ(charlie.results().at(kAB).source_version, 3u);
}

TEST(PairBoard, LeavingTheNetworkVoidsEveryClaim) {
  PairBoard bravo = holdingBoth("bravo");
  bravo.claimSeen("alpha", {kAB, 1, 2}, t0);
  bravo.leftNetwork();
  EXPECT_EQ(bravo.step(t0 + 1s).claims.size(), 1u);
}

TEST(PairBoard, AReplayedEstimateForOldMapsIsRefusedEvenWithNoResultHeld) {
  PairBoard charlie("charlie", timings());
  charlie.mapAnnounced("alpha", 1);
  charlie.mapAnnounced("bravo", 3);
  EXPECT_EQ(charlie.estimateSeen(resultOf({kAB, 1, 2}, "alpha")), PairBoard::Offer::Outdated);
  EXPECT_TRUE(charlie.results().empty());
}

TEST(PairBoard, AnEstimateAheadOfTheAnnouncementIsHeldUntilItsVersionIsKnown) {
  PairBoard charlie("charlie", timings());
  charlie.mapAnnounced("alpha", 1);
  EXPECT_EQ(charlie.estimateSeen(resultOf({kAB, 1, 2}, "alpha")), PairBoard::Offer::Pending);
  EXPECT_EQ(charlie.estimateSeen(resultOf({kAB, 1, 5}, "bravo")), PairBoard::Offer::Pending);
  EXPECT_TRUE(charlie.results().empty()) << "nothing stored before bravo's version is known";
  const auto stored = charlie.mapAnnounced("bravo", 2);
  ASSERT_EQ(stored.size(), 1u) << "the estimate for version 2 is stored, the one for 5 dropped";
  EXPECT_EQ(stored[0].computed_by, "alpha");
  EXPECT_EQ(charlie.results().at(kAB).source_version, 2u);
  EXPECT_TRUE(charlie.mapAnnounced("bravo", 5).empty()) << "the dropped one does not come back";
}

TEST(PairBoard, AnUnreliableAnswerForNewMapsDoesNotReplaceAReliableOne) {
  // A map update that gave no reliable match (a tilted scan, a bad SLAM
  // session) once replaced a good transform.
  PairBoard b = holdingBoth("alpha");
  ASSERT_EQ(b.estimateSeen(resultOf({kAB, 1, 2}, "bravo", 7.0)), PairBoard::Offer::Stored);
  b.mapAnnounced("bravo", 3);
  b.mapHeld("bravo");
  AgreedTransform bad = resultOf({kAB, 1, 3}, "bravo", 99.0);
  bad.reliable = false;
  bad.reason = "only 2 slice pairs agree (need 3)";
  ASSERT_EQ(b.estimateSeen(bad), PairBoard::Offer::Stored);

  ASSERT_EQ(b.results().size(), 1u);
  EXPECT_TRUE(b.results().at(kAB).reliable);
  EXPECT_EQ(b.results().at(kAB).T_target_source.x, 7.0) << "the reliable transform stays";
  const PairStatus s = b.status(kAB, t0);
  EXPECT_EQ(s.state, PairState::Kept);
  EXPECT_EQ(s.why, bad.reason);
  // The current versions have their answer: nobody computes them again.
  EXPECT_TRUE(b.step(t0).claims.empty());
  EXPECT_TRUE(b.step(t0 + 20s).claims.empty());
  EXPECT_EQ(b.estimateSeen(bad), PairBoard::Offer::Duplicate);

  // A reliable answer for still newer maps replaces it as usual.
  b.mapAnnounced("bravo", 4);
  b.mapHeld("bravo");
  EXPECT_EQ(b.status(kAB, t0).state, PairState::Stale) << "recomputed for version 4";
  ASSERT_EQ(b.estimateSeen(resultOf({kAB, 1, 4}, "bravo", 8.0)), PairBoard::Offer::Stored);
  EXPECT_EQ(b.results().at(kAB).T_target_source.x, 8.0);
  EXPECT_EQ(b.status(kAB, t0).state, PairState::Agreed);
  EXPECT_TRUE(b.keptBeside().empty());
}

TEST(PairBoard, WithNoReliableAnswerBeforeAnUnreliableOneIsStored) {
  PairBoard b = holdingBoth("alpha");
  AgreedTransform none = resultOf({kAB, 1, 2}, "bravo");
  none.reliable = false;
  none.reason = "ambiguous";
  ASSERT_EQ(b.estimateSeen(none), PairBoard::Offer::Stored);
  EXPECT_FALSE(b.results().at(kAB).reliable);
  EXPECT_EQ(b.status(kAB, t0).state, PairState::Agreed);
  EXPECT_TRUE(b.step(t0).claims.empty());
}
