// Sending one's own map without a network: requests queue slices once, a
// slice still on its way (leaving the flow controller, or coming to a late
// reader from the writer's history) is not queued again, a full writer holds
// the rest for later, and a new map version drops the old queue.
#include <gtest/gtest.h>

#include "clock_start.hpp"
#include "map_sender.hpp"

using namespace tomomap;
using namespace tomomap::daemon;
using namespace std::chrono_literals;

namespace {

/// An offer of `slices` slices of `parts` samples each, without a real map.
transport::MapOffer fakeOffer(int slices, int parts, uint64_t version) {
  transport::MapOffer o;
  o.announcement.version(version);
  for (int k = 0; k < slices; ++k) {
    wire::SliceEntry e;
    e.slice(k);
    e.parts(static_cast<uint16_t>(parts));
    e.bytes(static_cast<uint32_t>(1000 * parts));
    o.announcement.slices().push_back(e);
    for (int p = 0; p < parts; ++p) {
      wire::SliceFeatures s;
      s.slice(k);
      s.part(static_cast<uint16_t>(p));
      s.parts(static_cast<uint16_t>(parts));
      s.version(version);
      o.samples[k].push_back(s);
    }
  }
  transport::bundleOffer(o);  // sample_bytes 0: no sample has room for another, one part a sample
  return o;
}

/// 1000 bytes a sample at 80 kbit/s, of which new samples get 85 %: each
/// sample takes about 0.12 s to leave.
size_t thousand(const wire::SliceFeatures&) { return 1000; }

struct Wire {
  std::vector<std::pair<int, int>> sent;  ///< (slice, part)
  size_t room = 1000;                     ///< samples the writer takes before it is full
  /// Returns the sample's sequence number in the writer's stream (from 1), 0 when full.
  uint64_t publish(const wire::SliceFeatures& s) {
    if (room == 0) return 0;
    --room;
    sent.emplace_back(s.slice(), s.part());
    return sent.size();
  }
  /// `m` hands this wire what it would send at `at`, 1000 bytes a sample.
  void take(MapSender& m, Clock::time_point at) {
    m.pump([this](const wire::SliceFeatures& s) { return publish(s); }, thousand, at);
  }
};

/// Requests in these tests come from a requester that has heard nothing for long.
constexpr Clock::duration kStalled = std::chrono::seconds(60);

}  // namespace

TEST(MapSender, SendsWhatWasAskedForOnceInOrder) {
  MapSender m(80, 1s);
  m.setOffer(fakeOffer(3, 2, 9));
  EXPECT_EQ(m.request("bravo", 9, {2, 0}, kStalled, t0), 2u);
  EXPECT_EQ(m.request("bravo", 9, {0}, kStalled, t0), 1u) << "asked twice before it left: queued once";
  EXPECT_EQ(m.queued(), 4u) << "two samples a slice";
  Wire w;
  w.take(m, t0);
  EXPECT_EQ(w.sent, (std::vector<std::pair<int, int>>{{2, 0}, {2, 1}, {0, 0}, {0, 1}}));
  EXPECT_EQ(m.bytesSent(), 4000u);
  EXPECT_EQ(m.samplesSent(), 4u);
  EXPECT_EQ(m.queued(), 0u);
}

TEST(MapSender, ASliceStillOnItsWayIsNotSentAgain) {
  MapSender m(80, 1s);
  m.setOffer(fakeOffer(2, 1, 9));
  m.request("bravo", 9, {}, kStalled, t0);  // everything
  Wire w;
  w.take(m, t0);
  ASSERT_EQ(w.sent.size(), 2u);
  // Slice 1 leaves the controller at 0.24 s. bravo's window: both slices
  // leave (0.24 s) with repair slack (x 1.5), ten repair rounds (10 s) and
  // 1 s of grace: a request before 11.35 s crossed them, a later one means
  // slice 1 was lost.
  m.request("bravo", 9, {1}, kStalled, t0 + 11s);
  EXPECT_EQ(m.queued(), 0u);
  m.request("bravo", 9, {1}, kStalled, t0 + 11400ms);
  EXPECT_EQ(m.queued(), 1u);
}

TEST(MapSender, ASliceTheRequestersReaderHasPassedIsSentAgainAtOnce) {
  MapSender m(80, 1s);
  m.setOffer(fakeOffer(3, 2, 9));
  m.request("bravo", 9, {}, kStalled, t0);
  Wire w;
  w.take(m, t0);
  w.take(m, t0 + 1s);
  ASSERT_EQ(w.sent.size(), 6u);  // slice 0 is samples 1-2, slice 1 samples 3-4, slice 2 samples 5-6
  // At 2 s, well within bravo's window, bravo lacks slices 1 and 2 and has
  // taken samples up to number 5: its reader delivers in order, so slice 1
  // (last written as 4) will not come; slice 2's last part (6) may.
  m.request("bravo", 9, {1, 2}, 2s, t0 + 2s, /*received_through=*/5);
  EXPECT_EQ(m.queued(), 2u) << "slice 1's two samples";
  EXPECT_EQ(m.resends(), 2u);
  w.take(m, t0 + 2s);
  EXPECT_EQ(w.sent.back(), std::make_pair(1, 1));
  // The same request again: slice 1's new copy (7, 8) is on its way.
  m.request("bravo", 9, {1, 2}, 2s, t0 + 2100ms, /*received_through=*/5);
  EXPECT_EQ(m.queued(), 0u);
}

TEST(MapSender, AFullWriterHoldsTheRestForTheNextCall) {
  MapSender m(80, 1s);
  m.setOffer(fakeOffer(2, 2, 9));
  m.request("bravo", 9, {}, kStalled, t0);
  Wire w;
  w.room = 3;
  w.take(m, t0);
  EXPECT_EQ(w.sent.size(), 3u);
  EXPECT_EQ(m.queued(), 1u);
  w.room = 10;
  w.take(m, t0 + 50ms);
  EXPECT_EQ(w.sent.back(), std::make_pair(1, 1)) << "the slice's last part follows on";
  EXPECT_EQ(m.queued(), 0u);
}

TEST(MapSender, ANewVersionDropsTheOldQueueAndOldRequests) {
  MapSender m(80, 1s);
  m.setOffer(fakeOffer(3, 1, 9));
  m.request("bravo", 9, {}, kStalled, t0);
  m.setOffer(fakeOffer(3, 1, 10));
  EXPECT_EQ(m.queued(), 0u);
  EXPECT_EQ(m.request("bravo", 9, {0, 1}, kStalled, t0), 0u) << "a request for the old version";
  EXPECT_EQ(m.request("bravo", 10, {0, 7}, kStalled, t0), 1u) << "slice 7 does not exist";
  EXPECT_EQ(m.queued(), 1u);
}

TEST(MapSender, ALateReaderGetsTheHistoryInsteadOfAResend) {
  MapSender m(80, 1s);
  m.setOffer(fakeOffer(4, 1, 9));
  m.request("bravo", 9, {}, kStalled, t0);
  Wire w;
  w.take(m, t0);
  ASSERT_EQ(w.sent.size(), 4u);  // leave at 0.12 ... 0.47 s
  // charlie matched after they left and asks for everything at 2 s: the
  // history reaches it at the stream's rate (0.47 s) with repair slack
  // (x 1.5), ten repair rounds and the grace: by 13.7 s.
  m.request("charlie", 9, {}, kStalled, t0 + 2s);
  EXPECT_EQ(m.queued(), 0u) << "the durable history is on its way to charlie";
  m.request("charlie", 9, {3}, kStalled, t0 + 13s);
  EXPECT_EQ(m.queued(), 0u) << "still within charlie's window";
  m.request("charlie", 9, {3}, kStalled, t0 + 13800ms);
  EXPECT_EQ(m.queued(), 1u) << "overdue: lost at charlie, sent again";
  EXPECT_EQ(m.resends(), 1u);
}

TEST(MapSender, AStalledReaderIsAnsweredOnceItsCopyIsOverdue) {
  MapSender m(80, 1s);
  m.setOffer(fakeOffer(2, 1, 9));
  m.request("bravo", 9, {}, kStalled, t0);  // window: 0.24 s x 1.5 + 10 s of repair rounds + 1 s of grace
  Wire w;
  w.take(m, t0);
  m.request("bravo", 9, {0}, kStalled, t0 + 5s);
  EXPECT_EQ(m.queued(), 0u) << "slice 0 left at 0.12 s: RTPS is still repairing it";
  m.request("bravo", 9, {0}, kStalled, t0 + 11400ms);
  EXPECT_EQ(m.queued(), 1u);
  w.take(m, t0 + 11400ms);
  m.request("bravo", 9, {0}, kStalled, t0 + 11500ms);
  EXPECT_EQ(m.queued(), 0u) << "the resend is on its way";
}

TEST(MapSender, StartsOnceEveryLivePeerHasMatchedOrAfterAWait) {
  MapSender m(80, 1s);
  m.setOffer(fakeOffer(2, 1, 9));
  EXPECT_FALSE(m.mayStart(2, 2, t0)) << "nothing queued";
  m.request("bravo", 9, {}, kStalled, t0);
  EXPECT_FALSE(m.mayStart(1, 2, t0)) << "charlie is up but its reader has not matched yet";
  EXPECT_TRUE(m.mayStart(2, 2, t0 + 1s));
  EXPECT_TRUE(m.mayStart(1, 2, t0 + 6s)) << "a reader that never matches does not hold the others back";
}

TEST(MapSender, FeedsTheWriterAtTheStreamRateLeavingRoomForRepairs) {
  MapSender m(80, 1s);
  m.setOffer(fakeOffer(20, 1, 9));
  m.request("bravo", 9, {}, kStalled, t0);
  Wire w;
  w.take(m, t0);
  // 0.12 s a sample, at most 0.5 s ahead: five samples now, not twenty.
  EXPECT_EQ(w.sent.size(), 5u);
  w.take(m, t0 + 1s);
  EXPECT_EQ(w.sent.size(), 10u) << "the first five have left by 1 s: five more, 0.5 s ahead again";
}

TEST(MapSender, ARequesterThatIsStillReceivingIsLeftToTheRepairs) {
  MapSender m(80, 1s);
  m.setOffer(fakeOffer(2, 1, 9));
  m.request("bravo", 9, {}, kStalled, t0);
  Wire w;
  w.take(m, t0);
  m.request("bravo", 9, {0}, 3s, t0 + 20s);
  EXPECT_EQ(m.queued(), 0u) << "bravo received something 3 s ago: RTPS holds what follows a gap";
  m.request("bravo", 9, {0}, 15s, t0 + 20s);
  EXPECT_EQ(m.queued(), 1u);
}

TEST(MapSender, APeerThatAskedForTheCurrentVersionHoldsItsAnnouncement) {
  MapSender s(80, 1s);
  s.setOffer(fakeOffer(3, 1, 7));
  const auto now = Clock::now();
  EXPECT_TRUE(s.informed({})) << "no live peer needs it";
  EXPECT_FALSE(s.informed({"bravo"}));
  s.request("bravo", 6, {}, 0s, now);
  EXPECT_FALSE(s.informed({"bravo"})) << "asked about an older version";
  s.request("bravo", 7, {1}, 0s, now);
  EXPECT_TRUE(s.informed({"bravo"}));
  EXPECT_FALSE(s.informed({"bravo", "charlie"}));
  s.forget("bravo");  // it came up again: a restart loses what it held
  EXPECT_FALSE(s.informed({"bravo"}));
  s.request("bravo", 7, {}, 0s, now);
  s.setOffer(fakeOffer(3, 1, 8));
  EXPECT_FALSE(s.informed({"bravo"})) << "a new version is news to everyone";
}

TEST(MapSender, ARequestForASliceThatRidesInAnotherSampleSendsThatSample) {
  MapSender m(80, 1s);
  transport::MapOffer o = fakeOffer(3, 1, 9);
  o.sample_bytes = 1000;  // three empty parts fit one sample
  transport::bundleOffer(o);
  ASSERT_EQ(o.bundles.size(), 1u);
  m.setOffer(o);
  EXPECT_EQ(m.request("bravo", 9, {2, 1}, kStalled, t0), 2u);
  EXPECT_EQ(m.queued(), 1u);
  Wire w;
  w.take(m, t0);
  EXPECT_EQ(w.sent, (std::vector<std::pair<int, int>>{{0, 0}})) << "slice 0's sample, with slices 1 and 2 riding";
  // Slice 0 is in that sample too: asked for now, it is on its way.
  m.request("bravo", 9, {0}, kStalled, t0 + 1s);
  EXPECT_EQ(m.queued(), 0u);
}
