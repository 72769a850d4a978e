// Receiving a peer's map without a network: a stream that arrives before its
// announcement (they travel on different topics) is held and taken in, not
// dropped and asked for again.
#include <gtest/gtest.h>

#include <algorithm>

#include "clock_start.hpp"
#include "core/matcher.hpp"
#include "peer_maps.hpp"
#include "synth/synth.hpp"
#include "transport/map_offer.hpp"

using namespace tomomap;
using namespace tomomap::daemon;
using namespace std::chrono_literals;

namespace {

/// bravo's offer of a small generated map at g = 0.1.
const transport::MapOffer& bravoOffer() {
  static const transport::MapOffer offer = [] {
    synth::SceneParams sp;
    sp.scale = 0.5;
    const Points points = synth::scanScene(synth::makeScene(sp), synth::noiseLevel("low"), 1).front().points;
    MatchParams p;
    p.grid = 0.1;
    return transport::makeOffer("bravo", describeMap(points, p), {}, 1000000, 4000);
  }();
  return offer;
}

std::vector<wire::SliceFeatures> samplesOf(const transport::MapOffer& offer) {
  std::vector<wire::SliceFeatures> all;
  for (const auto& [k, samples] : offer.samples) all.insert(all.end(), samples.begin(), samples.end());
  return all;
}

/// Slices a request asks for (an empty list asks for every announced slice).
size_t asked(const wire::ChunkRequest& r) {
  return r.slices().empty() ? bravoOffer().announcement.slices().size() : r.slices().size();
}

}  // namespace

TEST(PeerMaps, SlicesBeforeTheirAnnouncementAreHeldAndTakenIn) {
  Log log(LogLevel::Error);
  PeerMaps peers("alpha", log, 256u << 20);
  const auto& offer = bravoOffer();
  const auto all = samplesOf(offer);
  ASSERT_GT(all.size(), 10u);
  // The first two thirds of bravo's stream arrive before its announcement.
  const size_t early = all.size() * 2 / 3;
  for (size_t i = 0; i < early; ++i) {
    const auto got = peers.receive(all[i], 1000, i + 1, t0);
    EXPECT_FALSE(got.rejection);
    EXPECT_FALSE(got.completed);
  }
  EXPECT_FALSE(peers.version("bravo")) << "nothing announced yet";
  const auto announced = peers.announce(offer.announcement, t0 + 50ms);
  ASSERT_TRUE(announced.new_version);
  ASSERT_TRUE(announced.request);
  EXPECT_FALSE(announced.request->slices().empty()) << "asks for what is missing, not everything";
  EXPECT_LT(announced.request->slices().size(), offer.announcement.slices().size());
  for (size_t i = early; i < all.size(); ++i) peers.receive(all[i], 1000, i + 1, t0 + 100ms);
  ASSERT_NE(peers.features("bravo"), nullptr) << "the map is complete without any resend";
}

TEST(PeerMaps, HeldSlicesAreBoundedByThePeerMemoryBudgetAndByTime) {
  Log log(LogLevel::Error);
  const auto& offer = bravoOffer();
  const auto all = samplesOf(offer);
  // A budget of three samples' bytes: the rest of the early stream is not held.
  PeerMaps small("alpha", log, 3000);
  for (const auto& s : all) small.receive(s, 1000, 1, t0);
  const auto a = small.announce(offer.announcement, t0 + 50ms);
  ASSERT_TRUE(a.request);
  EXPECT_GE(asked(*a.request), offer.announcement.slices().size() - 3);

  // Samples held longer than an announcement can lag are a resend of an old
  // version meant for another peer: dropped.
  PeerMaps late("alpha", log, 256u << 20);
  for (const auto& s : all) late.receive(s, 1000, 1, t0);
  late.receive(all.front(), 1000, 1, t0 + 90s);  // restarts the hold
  const auto b = late.announce(offer.announcement, t0 + 90s);
  ASSERT_TRUE(b.request);
  EXPECT_GE(asked(*b.request), offer.announcement.slices().size() - 1);
}

TEST(PeerMaps, ARequestSaysHowFarTheOwnersStreamWasTaken) {
  Log log(LogLevel::Error);
  PeerMaps peers("alpha", log, 256u << 20);
  const auto& offer = bravoOffer();
  const auto all = samplesOf(offer);
  const auto a = peers.announce(offer.announcement, t0);
  ASSERT_TRUE(a.request);
  EXPECT_EQ(a.request->received_through(), 0u) << "nothing taken yet";
  // bravo's writer numbered its samples 1, 2, ...; the reader handed on all
  // but the fifth (written as number 5), and the last one taken is number 40.
  for (size_t i = 0; i < 40; ++i)
    if (i != 4) peers.receive(all[i], 1000, i + 1, t0 + 100ms);
  const auto due = peers.askNow("bravo", t0 + 200ms);
  ASSERT_TRUE(due);
  EXPECT_EQ(due->received_through(), 40u);
  EXPECT_TRUE(std::count(due->slices().begin(), due->slices().end(), all[4].slice()))
      << "the slice of the sample the reader lost is asked for";

  // A peer that comes again has a new writer, numbering from 1.
  peers.setAlive("bravo", true);
  const auto again = peers.askNow("bravo", t0 + 300ms);
  ASSERT_TRUE(again);
  EXPECT_EQ(again->received_through(), 0u);
}

TEST(PeerMaps, APeerThatComesIsAskedForItsOwnMapAlone) {
  Log log(LogLevel::Error);
  PeerMaps peers("alpha", log, 256u << 20);
  const auto& offer = bravoOffer();
  const auto all = samplesOf(offer);
  peers.announce(offer.announcement, t0);
  // charlie's participant comes: nothing of charlie's is announced, and
  // bravo, which heard our request, is not asked again on its account.
  EXPECT_FALSE(peers.askNow("charlie", t0 + 100ms));
  // bravo's participant comes (again): what we asked it may have been lost.
  const auto asked_bravo = peers.askNow("bravo", t0 + 200ms);
  ASSERT_TRUE(asked_bravo);
  EXPECT_EQ(asked_bravo->owner(), "bravo");
  EXPECT_EQ(asked(*asked_bravo), offer.announcement.slices().size()) << "every slice: none came yet";
  for (size_t i = 0; i < all.size(); ++i) peers.receive(all[i], 1000, i + 1, t0 + 300ms);
  ASSERT_TRUE(peers.features("bravo"));
  EXPECT_FALSE(peers.askNow("bravo", t0 + 400ms)) << "a complete map is not asked for";
}

TEST(PeerMaps, ALivePeerWhoseAnnouncementDoesNotComeIsAskedForItWithBackOff) {
  Log log(LogLevel::Error);
  PeerMaps peers("alpha", log, 256u << 20);
  peers.setAlive("bravo", true);
  auto announcementAsks = [&](Clock::time_point at) {
    size_t n = 0;
    for (const auto& r : peers.due(1s, at))
      if (r.owner() == "bravo" && r.version() == PeerMaps::kNoVersion && r.requester() == "alpha") ++n;
    return n;
  };
  EXPECT_EQ(announcementAsks(t0), 0u) << "durability brings it within a second or two";
  EXPECT_EQ(announcementAsks(t0 + 4s), 0u);
  EXPECT_EQ(announcementAsks(t0 + 5100ms), 1u);
  EXPECT_EQ(announcementAsks(t0 + 14s), 0u) << "the next ask waits twice as long";
  EXPECT_EQ(announcementAsks(t0 + 15200ms), 1u);
  // The announcement comes: no more asking for it.
  peers.announce(bravoOffer().announcement, t0 + 16s);
  EXPECT_EQ(announcementAsks(t0 + 60s), 0u);
  // bravo restarts: its new participant is waited for, then asked, anew.
  peers.setAlive("bravo", false);
  EXPECT_EQ(announcementAsks(t0 + 61s), 0u) << "not alive";
}

// A reload that removes a peer from the config leaves nothing of it behind:
// not its map, its transfers, its liveness nor its last sighting.
TEST(PeerMaps, APeerDroppedByAReloadLeavesNothingBehind) {
  Log log(LogLevel::Error);
  PeerMaps peers("alpha", log, 256u << 20);
  const auto& offer = bravoOffer();
  const auto all = samplesOf(offer);
  peers.setAlive("bravo", true);
  peers.seen("bravo", 1000);
  peers.announce(offer.announcement, t0);
  for (size_t i = 0; i < all.size(); ++i) peers.receive(all[i], 1000, i + 1, t0 + 300ms);
  ASSERT_TRUE(peers.features("bravo"));
  const transport::PeerAddress bravo{"bravo", "10.0.0.2", 7400};
  ASSERT_EQ(peers.status(bravo)["transfers"].size(), 1u);

  peers.retain([](const std::string& id) { return id != "bravo"; });
  EXPECT_FALSE(peers.features("bravo"));
  EXPECT_FALSE(peers.version("bravo"));
  EXPECT_EQ(peers.aliveCount(), 0u);
  const auto s = peers.status(bravo);
  EXPECT_FALSE(s["alive"].get<bool>());
  EXPECT_FALSE(s.contains("last_seen_ms")) << s.dump();
  EXPECT_TRUE(s["transfers"].empty()) << s.dump();
  EXPECT_EQ(peers.totals().maps, 0u);
}
