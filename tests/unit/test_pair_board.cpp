// Who computes which pair, replayed without a network: claims that race, a
// claimer that disappears, maps that change while a pair is computed. The time
// is injected; nothing sleeps.
#include <gtest/gtest.h>

#include <iostream>
#include <map>
#include <set>

#include "clock_start.hpp"
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
  EXPECT_EQ(charlie.estimateSeen(resultOf({kAB, 1, 2}, "alpha")), PairBoard::Offer::Pending);
  EXPECT_EQ(charlie.results().at(kAB).source_version, 3u);
  EXPECT_TRUE(charlie.mapAnnounced("bravo", 4).empty()) << "bravo moved on to 4: the estimate for 2 is dropped";
  EXPECT_TRUE(charlie.mapAnnounced("bravo", 2).empty()) << "and does not come back";
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
  EXPECT_EQ(charlie.estimateSeen(resultOf({kAB, 1, 2}, "alpha")), PairBoard::Offer::Pending);
  EXPECT_TRUE(charlie.results().empty());
  EXPECT_TRUE(charlie.mapAnnounced("alpha", 7).empty());
  EXPECT_TRUE(charlie.results().empty());
}

// Seen in the soak run (tests/link/soak.py): bravo's map grew, bravo computed
// alpha<-bravo for its new version and broadcast it, and the estimate reached
// charlie a millisecond before bravo's announcement did. Charlie refused it as
// outdated, everyone else stored it, nobody computed the pair again: charlie
// held it "stale" for good.
TEST(PairBoard, AnEstimateForANewVersionAheadOfItsAnnouncementIsStoredWhenTheAnnouncementComes) {
  PairBoard charlie("charlie", timings());
  charlie.mapAnnounced("alpha", 1);
  charlie.mapAnnounced("bravo", 2);
  ASSERT_EQ(charlie.estimateSeen(resultOf({kAB, 1, 2}, "bravo")), PairBoard::Offer::Stored);
  EXPECT_EQ(charlie.estimateSeen(resultOf({kAB, 1, 3}, "bravo", 2.0)), PairBoard::Offer::Pending);
  EXPECT_EQ(charlie.results().at(kAB).source_version, 2u) << "nothing replaced before bravo's 3 is announced";
  const auto stored = charlie.mapAnnounced("bravo", 3);
  ASSERT_EQ(stored.size(), 1u);
  EXPECT_EQ(charlie.results().at(kAB).source_version, 3u);
  EXPECT_EQ(charlie.status(kAB, t0).state, PairState::Agreed);
}

TEST(PairBoard, AnEstimateAheadOfBothAnnouncementsWaitsForTheSecond) {
  PairBoard charlie("charlie", timings());
  charlie.mapAnnounced("alpha", 1);
  charlie.mapAnnounced("bravo", 2);
  EXPECT_EQ(charlie.estimateSeen(resultOf({kAB, 4, 5}, "alpha")), PairBoard::Offer::Pending);
  EXPECT_TRUE(charlie.mapAnnounced("alpha", 4).empty()) << "bravo's 5 is not here yet";
  EXPECT_EQ(charlie.mapAnnounced("bravo", 5).size(), 1u);
  EXPECT_EQ(charlie.results().at(kAB).target_version, 4u);
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

TEST(ComputeOrder, EveryAgentIsFirstForItsShareOfThePairs) {
  for (const size_t n : {2u, 3u, 6u, 10u, 30u}) {
    std::vector<std::string> fleet;
    for (size_t i = 0; i < n; ++i) fleet.push_back("agent" + std::string(i < 10 ? "0" : "") + std::to_string(i));
    std::map<std::string, size_t> first;
    for (size_t i = 0; i < n; ++i)
      for (size_t j = i + 1; j < n; ++j) {
        const auto order = computeOrder({fleet[i], fleet[j]}, fleet);
        ASSERT_EQ(order.size(), n);
        EXPECT_EQ(std::set<std::string>(order.begin(), order.end()).size(), n) << "each agent once";
        ++first[order.front()];
      }
    size_t most = 0, least = n * n;
    for (const auto& id : fleet) most = std::max(most, first[id]), least = std::min(least, first[id]);
    EXPECT_LE(most - least, 1u) << n << " agents";
  }
  EXPECT_TRUE(computeOrder({"alpha", "zulu"}, {"alpha", "bravo"}).empty()) << "zulu is not in this fleet";
}

namespace {

/// A board of `me` in the fleet alpha, bravo, charlie, delta (those in `up`
/// up), holding every map in `maps` at version 1.
PairBoard fleetBoard(const std::string& me, const std::vector<std::string>& maps,
                     const std::vector<std::string>& up = {"alpha", "bravo", "charlie", "delta"}) {
  PairBoard b(me, timings());
  b.setFleet({"alpha", "bravo", "charlie", "delta"});
  for (const auto& id : {"alpha", "bravo", "charlie", "delta"})
    if (id != me && std::find(up.begin(), up.end(), id) == up.end()) b.agentGone(id);
  for (const auto& id : maps) {
    if (id == me) {
      b.ownMap(1);
    } else {
      b.mapAnnounced(id, 1);
      b.mapHeld(id);
    }
  }
  return b;
}

}  // namespace

TEST(PairBoard, OnlyTheAgentWhoseTurnItIsClaimsThenTheNextAfterATimeout) {
  const std::vector<std::string> maps{"alpha", "bravo", "charlie"};
  const std::vector<std::string> three{"alpha", "bravo", "charlie"};
  // alpha<-bravo in the fleet of three: charlie first, then alpha, then bravo.
  EXPECT_EQ(computeOrder(kAB, three), (std::vector<std::string>{"charlie", "alpha", "bravo"}));
  PairBoard alpha = fleetBoard("alpha", maps, three), bravo = fleetBoard("bravo", maps, three);
  for (auto* b : {&alpha, &bravo})
    for (const PairAt& c : b->step(t0).claims) EXPECT_NE(c.pair, kAB) << "charlie's turn";

  // charlie holds the maps but never claims (stuck, or busy with other pairs):
  // after one claim timeout the pair is alpha's, after two bravo's.
  PairBoard idle_alpha = fleetBoard("alpha", {"alpha", "bravo"}, three);
  PairBoard idle_bravo = fleetBoard("bravo", {"alpha", "bravo"}, three);
  EXPECT_TRUE(idle_alpha.step(t0).claims.empty());
  EXPECT_TRUE(idle_bravo.step(t0).claims.empty());
  EXPECT_TRUE(idle_alpha.step(t0 + 7s).claims.empty());
  ASSERT_EQ(idle_alpha.step(t0 + 8s).claims.size(), 1u) << "alpha is second in line";
  EXPECT_TRUE(idle_bravo.step(t0 + 8s).claims.empty());
  EXPECT_EQ(idle_bravo.step(t0 + 16s).claims.size(), 1u) << "bravo is third in line";

  // A peer not discovered yet is presumed up: it may be on the pair already
  // (a busy machine discovers in seconds); alpha waits its turn.
  PairBoard undiscovered("alpha", timings());
  undiscovered.setFleet({"bravo", "charlie"});
  undiscovered.ownMap(1);
  undiscovered.mapAnnounced("bravo", 1);
  undiscovered.mapHeld("bravo");
  EXPECT_TRUE(undiscovered.step(t0).claims.empty());
  EXPECT_EQ(undiscovered.step(t0 + 8s).claims.size(), 1u);

  // charlie's participant is gone: alpha is first among those up, at once.
  PairBoard fresh = fleetBoard("alpha", {"alpha", "bravo"}, three);
  fresh.agentGone("charlie");
  const BoardStep now = fresh.step(t0);
  ASSERT_EQ(now.claims.size(), 1u);
  EXPECT_EQ(now.claims[0].pair, kAB);
}

TEST(PairBoard, ClaimsOnlyThePairItIsAboutToComputeJoiningUnconnectedAgentsFirst) {
  // Alone in the fleet: every pair is alpha's turn, and it claims one at a time.
  PairBoard alpha = fleetBoard("alpha", {"alpha", "bravo", "charlie", "delta"}, {"alpha"});
  // alpha<-charlie and bravo<-charlie are agreed: alpha, bravo and charlie are
  // one component, delta alone; alpha<-bravo (key order's first) adds nothing.
  for (const auto& [t, s] : {PairKey{"alpha", "charlie"}, PairKey{"bravo", "charlie"}})
    ASSERT_EQ(alpha.estimateSeen(resultOf({{t, s}, 1, 1}, "bravo")), PairBoard::Offer::Stored);
  std::vector<PairKey> order;
  auto now = t0;
  for (int round = 0; round < 4; ++round) {
    const BoardStep claim = alpha.step(now);
    if (claim.claims.empty()) break;
    ASSERT_EQ(claim.claims.size(), 1u) << "one claim at a time";
    const BoardStep go = alpha.step(now += 500ms);
    ASSERT_TRUE(go.compute);
    EXPECT_TRUE(alpha.step(now).claims.empty()) << "nothing else claimed while computing";
    order.push_back(go.compute->pair);
    alpha.computed(resultOf(*go.compute, "alpha"));
  }
  ASSERT_EQ(order.size(), 4u);
  EXPECT_EQ(order[0], (PairKey{"alpha", "delta"})) << "the pair that brings delta into the frame";
  EXPECT_EQ(order[1], (PairKey{"alpha", "bravo"})) << "then the rest, which close cycles, in key order";
}

namespace {

/// N boards that hold every map, exchanging claims and estimates after every
/// round of 100 ms; a match takes 3 s. `dies` stops stepping when it starts
/// its first match (a killed daemon); with `gone_after` the others are told
/// its participant left that long after (liveliness), without it only its
/// claim's timeout tells them.
struct FleetRun {
  std::vector<std::string> ids;
  std::map<PairKey, int> computations;  ///< matches started per pair
  std::vector<size_t> per_agent;        ///< matches started per agent
  std::vector<size_t> agreed;           ///< current results per agent at the end
  double seconds = 0;                   ///< until every live agent held every pair
};

FleetRun simulateFleet(size_t n, std::optional<size_t> dies = {}, std::optional<Clock::duration> gone_after = {}) {
  FleetRun run;
  for (size_t i = 0; i < n; ++i) run.ids.push_back("r" + std::string(i < 10 ? "0" : "") + std::to_string(i));
  std::vector<PairBoard> boards;
  for (const auto& me : run.ids) {
    boards.emplace_back(me, timings());
    boards.back().setFleet(run.ids);
    for (const auto& id : run.ids)
      if (id != me) boards.back().agentUp(id);
    for (const auto& id : run.ids) {
      if (id == me) {
        boards.back().ownMap(1);
      } else {
        boards.back().mapAnnounced(id, 1);
        boards.back().mapHeld(id);
      }
    }
  }
  const size_t pairs = n * (n - 1) / 2;
  run.per_agent.assign(n, 0);
  std::vector<std::optional<std::pair<PairAt, Clock::time_point>>> running(n);
  std::optional<Clock::time_point> died;
  const size_t watcher = dies && *dies == 0 ? 1 : 0;
  auto now = t0;
  for (; boards[watcher].currentResults() < pairs && now < t0 + 3600s; now += 100ms) {
    std::vector<std::pair<size_t, PairAt>> claims;
    std::vector<AgreedTransform> results;
    for (size_t k = 0; k < n; ++k) {
      if (died && dies == k) continue;
      if (running[k] && now - running[k]->second >= 3s) {
        results.push_back(resultOf(running[k]->first, run.ids[k]));
        boards[k].computed(results.back());
        running[k].reset();
      }
      const BoardStep s = boards[k].step(now);
      for (const auto& c : s.claims) claims.emplace_back(k, c);
      if (s.compute) {
        running[k] = {*s.compute, now};
        ++run.computations[s.compute->pair];
        ++run.per_agent[k];
        if (dies == k) died = now;
      }
    }
    for (size_t k = 0; k < n; ++k) {
      if (died && gone_after && now - *died >= *gone_after && now - *died < *gone_after + 100ms)
        boards[k].agentGone(run.ids[*dies]);
      for (const auto& [from, c] : claims)
        if (from != k) boards[k].claimSeen(run.ids[from], c, now);
      for (const auto& r : results)
        if (r.computed_by != run.ids[k]) boards[k].estimateSeen(r);
    }
  }
  for (const auto& b : boards) run.agreed.push_back(b.currentResults());
  run.seconds = std::chrono::duration<double>(now - t0).count();
  return run;
}

}  // namespace

TEST(PairBoard, AFleetSimulatedComputesEachPairOnceSpreadEvenly) {
  // Each pair is computed once, no agent more than its share plus one, and
  // the fleet's time shrinks with its size.
  for (const size_t n : {3u, 6u, 10u, 30u}) {
    const FleetRun run = simulateFleet(n);
    const size_t pairs = n * (n - 1) / 2;
    for (const size_t held : run.agreed) EXPECT_EQ(held, pairs) << n << " agents";
    EXPECT_EQ(run.computations.size(), pairs);
    for (const auto& [pair, times] : run.computations) EXPECT_EQ(times, 1) << pairText(pair) << ", " << n << " agents";
    const size_t share = (pairs + n - 1) / n;
    for (size_t k = 0; k < n; ++k) EXPECT_LE(run.per_agent[k], share + 1) << run.ids[k] << ", " << n << " agents";
    std::cout << n << " agents, " << pairs << " pairs of 3 s: every pair agreed after " << run.seconds
              << " s (one agent alone: " << 3.5 * static_cast<double>(pairs) << " s)\n";
    EXPECT_LE(run.seconds, 3.6 * static_cast<double>(share) + 1) << n << " agents";
  }
}

TEST(PairBoard, AFleetSimulatedTakesOverTheMatchOfAnAgentKilledMidway) {
  // r02 is killed as it starts its first match. Told by liveliness (2 s) or
  // only by its claim running out (8 s), the others compute that pair, and
  // r02's other turns, once each; the abandoned match is the one done twice.
  for (const bool told : {true, false}) {
    const FleetRun run = simulateFleet(6, 2, told ? std::optional<Clock::duration>(2s) : std::nullopt);
    for (size_t k = 0; k < 6; ++k) {
      if (k == 2) continue;
      EXPECT_EQ(run.agreed[k], 15u) << run.ids[k] << (told ? ", told" : ", by timeout");
    }
    EXPECT_EQ(run.per_agent[2], 1u);
    int twice = 0;
    for (const auto& [pair, times] : run.computations) {
      EXPECT_LE(times, 2) << pairText(pair);
      twice += times == 2;
    }
    EXPECT_EQ(twice, 1) << "only the killed agent's match is done again";
    std::cout << (told ? "told by liveliness: " : "by claim timeout: ") << run.seconds << " s\n";
  }
}
