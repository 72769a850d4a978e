// Wire encoding, chunking and reassembly without a network.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "core/matcher.hpp"
#include "support.hpp"
#include "synth/synth.hpp"
#include "transport/map_offer.hpp"
#include "transport/participant.hpp"
#include "transport/reassembler.hpp"
#include "transport/wire_sizes.hpp"

using namespace tomomap;
using namespace tomomap::transport;

namespace {

/// A small generated map.
const Points& samplePoints() {
  static const Points points = [] {
    synth::SceneParams sp;
    sp.scale = 0.5;
    const synth::Scene scene = synth::makeScene(sp);
    return synth::scanScene(scene, synth::noiseLevel("low"), 1).front().points;
  }();
  return points;
}

MapFeatures describeAtDecimetre(const Points& map) {
  MatchParams p;
  p.grid = 0.1;
  return describeMap(map, p);
}

/// The sample map described at g = 0.1.
const MapFeatures& sampleMap() {
  static const MapFeatures f = describeAtDecimetre(samplePoints());
  return f;
}

Reassembler receiveAll(const MapOffer& offer, bool shuffle) {
  Reassembler r(offer.announcement);
  std::vector<wire::SliceFeatures> all;
  for (const auto& [k, samples] : offer.samples) all.insert(all.end(), samples.begin(), samples.end());
  if (shuffle) std::shuffle(all.begin(), all.end(), std::mt19937(7));
  for (const auto& s : all) EXPECT_FALSE(r.accept(s)) << r.accept(s).text();
  return r;
}

}  // namespace

TEST(SliceCodec, RoundTripGivesTheSameFeaturesInAnyOrder) {
  const MapFeatures& f = sampleMap();
  const MapOffer offer = makeOffer("alpha", f, {}, 1000000, 4000);
  EXPECT_FALSE(validate(offer.announcement)) << validate(offer.announcement).text();
  const Reassembler r = receiveAll(offer, /*shuffle=*/true);
  ASSERT_TRUE(r.complete());
  const MapFeatures back = r.build();
  ASSERT_EQ(back.slices.size(), f.slices.size());
  for (size_t i = 0; i < f.slices.size(); ++i) {
    EXPECT_EQ(back.slices[i].index, f.slices[i].index);
    ASSERT_EQ(back.slices[i].keypoints.size(), f.slices[i].keypoints.size());
    EXPECT_LT((back.slices[i].keypoints[0] - f.slices[i].keypoints[0]).norm(), 1e-4);
    EXPECT_EQ(cv::norm(back.slices[i].descriptors, f.slices[i].descriptors, cv::NORM_HAMMING), 0);
  }
  // Matching the received copy against the original finds the identity.
  MatchParams p;
  p.grid = 0.1;
  const MatchResult m = matchFeatures(f, back, p);
  ASSERT_TRUE(m.reliable) << m.reason;
  EXPECT_LT(std::hypot(m.T_target_source.x, m.T_target_source.y), 0.01);
}

TEST(SliceCodec, SamplesFitTheBudgetAndTheCheaperEncodingIsChosen) {
  const MapFeatures& f = sampleMap();
  const size_t budget = maxSampleBytes(1000, /*secure=*/true);  // 1 Mbit/s
  EXPECT_LE(budget, bytesPerPeriod(1000));
  const MapOffer offer = makeOffer("alpha", f, {}, 1000000, budget);
  size_t features = 0, occupancy = 0, full_parts = 0;
  for (const auto& [k, samples] : offer.samples)
    for (const auto& s : samples) {
      const size_t size = wire::SliceFeatures::getCdrSerializedSize(s);
      EXPECT_LE(size, budget);
      (s.encoding() == wire::SliceEncoding::OCCUPANCY ? occupancy : features)++;
      // Every part but a slice's last fills the sample: each datagram pays
      // its headers, so room left empty costs bytes on the link.
      if (s.part() + 1 < s.parts()) {
        ++full_parts;
        EXPECT_GT(size + kFeatureBytes + 3, budget) << "slice " << s.slice() << " part " << s.part();
      }
    }
  EXPECT_GT(full_parts, 0u) << "the sample map has slices larger than one sample";
  EXPECT_GT(occupancy + features, 0u);
  size_t feature_bytes = kFeatureBytes * f.featureCount();
  EXPECT_LE(offer.payload_bytes, feature_bytes) << "never more than sending every feature";
}

TEST(SliceCodec, InconsistentSamplesAreRejectedNotCrashed) {
  const MapOffer offer = makeOffer("alpha", sampleMap(), {}, 1000000, 4000);
  Reassembler r(offer.announcement);
  wire::SliceFeatures s = offer.samples.begin()->second.front();

  wire::SliceFeatures unknown = s;
  unknown.slice(100000);
  EXPECT_EQ(r.accept(unknown), Reject::NotAnnounced);
  EXPECT_EQ(r.accept(unknown).text(), "slice 100000 was not announced");
  wire::SliceFeatures parts = s;
  parts.parts(static_cast<uint16_t>(parts.parts() + 1));
  EXPECT_EQ(r.accept(parts), Reject::PartNumbering);
  wire::SliceFeatures mixed = s;
  mixed.features().resize(1);
  mixed.occupancy({1, 2, 3});
  EXPECT_EQ(r.accept(mixed), Reject::MixedEncoding);

  // A corrupted payload is caught by the CRC once the slice is whole.
  wire::SliceFeatures corrupt = s;
  if (!corrupt.features().empty()) corrupt.features()[0].descriptor()[0] ^= 0xff;
  if (!corrupt.occupancy().empty()) corrupt.occupancy()[corrupt.occupancy().size() / 2] ^= 0x5a;
  Rejection verdict;
  for (uint16_t p = 0; p < s.parts(); ++p) {
    wire::SliceFeatures x = p == s.part() ? corrupt : offer.samples.begin()->second[p];
    verdict = r.accept(x);
  }
  EXPECT_EQ(verdict, Reject::ChecksumMismatch);
  EXPECT_FALSE(r.complete());
  EXPECT_EQ(r.missing().size(), offer.announcement.slices().size());

  // Announcements that lie are refused before anything is allocated.
  wire::MapAnnouncement a = offer.announcement;
  a.grid(std::nan(""));
  EXPECT_EQ(validate(a), Reject::BadGridOrOrigin);
  a = offer.announcement;
  a.width(0);
  EXPECT_EQ(validate(a), Reject::BadRaster);
  a = offer.announcement;
  a.version(a.version() + 1);
  EXPECT_EQ(validate(a), Reject::VersionMismatch);
  a = offer.announcement;
  a.features().max_features(0);
  EXPECT_EQ(validate(a), Reject::BadFeatureSettings);
}

// The heights at which a map had no point (the slab between the building's
// floors) travel with it: a receiver judges the empty space a pose lands in
// as the owner does (enclosure.hpp). Announcements that lie
// about them are refused.
TEST(SliceCodec, TheHeightsAMapSawNothingAtTravelWithIt) {
  synth::SceneParams sp;
  sp.type = synth::WorldType::Room;
  const Points room = synth::scanScene(synth::makeScene(sp), synth::noiseLevel("low"), 1).front().points;
  Points storeys = room;  // the room again 6 m up, nothing between
  for (const auto& p : room) storeys.push_back(p + Eigen::Vector3f(0, 0, 6.0f));
  const MapFeatures f = describeAtDecimetre(storeys);
  ASSERT_EQ(f.occupancy.seen.size(), f.occupancy.cells.size());
  ASSERT_GT(std::count(f.occupancy.seen.begin(), f.occupancy.seen.end(), false), 0);
  const MapOffer offer = makeOffer("alpha", f, {}, 1000000, 4000);
  EXPECT_FALSE(validate(offer.announcement)) << validate(offer.announcement).text();
  const Reassembler r = receiveAll(offer, /*shuffle=*/false);
  ASSERT_TRUE(r.complete());
  EXPECT_EQ(r.build().occupancy.seen, f.occupancy.seen);

  const auto lie = [&](std::vector<int32_t> unseen) {
    wire::MapAnnouncement a = offer.announcement;
    a.unseen(std::move(unseen));
    a.version(mapVersion(a));
    return validate(a);
  };
  const int32_t sent = offer.announcement.slices().front().slice(), count = offer.announcement.slice_count();
  ASSERT_GE(offer.announcement.unseen().size(), 2u);
  const int32_t gap = offer.announcement.unseen().front();  // the slab's lowest slice
  EXPECT_EQ(lie({gap, gap, gap + 2, gap + 2}), Reject::None) << "two runs, apart";
  EXPECT_EQ(lie({gap, gap, gap + 1, gap + 1}), Reject::BadUnseen) << "two runs that are one";
  EXPECT_EQ(lie({gap + 2, gap + 2, gap, gap}), Reject::BadUnseen) << "out of order";
  EXPECT_EQ(lie({sent}), Reject::UnpairedUnseen) << "not in pairs";
  EXPECT_EQ(lie({sent}).text(), "announcement with an unseen run without its last slice");
  EXPECT_EQ(lie({sent, sent}), Reject::BadUnseen) << "over a slice it sends";
  EXPECT_EQ(lie({count, count}), Reject::BadUnseen) << "out of range";
  EXPECT_EQ(lie({-1, -1}), Reject::BadUnseen) << "out of range";
  EXPECT_NE(lie({-1, -1}).text().find("from slice -1"), std::string::npos) << lie({-1, -1}).text();
  EXPECT_EQ(lie({1, 0}), Reject::BadUnseen) << "a run upside down";
  EXPECT_EQ(lie({}), Reject::None) << "saying nothing: every height seen";
  wire::MapAnnouncement a = offer.announcement;  // other runs under the old version
  a.unseen({gap, gap});
  EXPECT_EQ(validate(a), Reject::VersionMismatch);
}

TEST(SliceCodec, ALevelledMapSaysItsUpAndTheReceiverUndoesItsLevelling) {
  // The map as a SLAM saved it, its first frame leaning 8 degrees: levelled before slicing.
  const Eigen::Quaterniond lean(Eigen::AngleAxisd(radians(8), Eigen::Vector3d(1, 2, 0).normalized()));
  const MapFeatures f = describeAtDecimetre(rotatePoints(samplePoints(), lean));
  ASSERT_TRUE(f.leveled) << degrees(f.tilt.angle);
  const MapOffer offer = makeOffer("alpha", f, {}, 1000000, 4000);
  EXPECT_FALSE(validate(offer.announcement)) << validate(offer.announcement).text();
  const MapFeatures back = receiveAll(offer, /*shuffle=*/false).build();
  EXPECT_TRUE(back.leveled);
  EXPECT_TRUE(back.slicedUp().isApprox(f.slicedUp(), 1e-12));
  EXPECT_LT(degrees(std::acos(back.slicedUp().dot(lean * Eigen::Vector3d::UnitZ()))), 0.5)
      << "the up it was levelled by is the lean's";
  EXPECT_EQ(sampleMap().slicedUp(), Eigen::Vector3d::UnitZ()) << "a level map is sliced as it is";

  // An up no map is levelled by (the map on its side) is refused; another up is another version.
  wire::MapAnnouncement a = offer.announcement;
  a.up({0.0, 1.0, 0.0});
  EXPECT_EQ(validate(a), Reject::BadUp);
  a.up({0.0, 0.0, 1.0});
  EXPECT_EQ(validate(a), Reject::VersionMismatch);
}

TEST(SliceCodec, AMapUpdateReusesTheSlicesThatDidNotChange) {
  // The robot's map gains a cabinet, inside its bounds.
  const Points updated = tomomap::test::withCabinet(samplePoints());
  const MapOffer before = makeOffer("alpha", sampleMap(), {}, 1000000, 4000);
  const MapFeatures changed = describeAtDecimetre(updated);
  const MapOffer after = makeOffer("alpha", changed, {}, 1000000, 4000);
  ASSERT_NE(before.announcement.version(), after.announcement.version());

  const Reassembler old = receiveAll(before, false);
  Reassembler next(after.announcement);
  const size_t taken = next.adopt(old);
  EXPECT_GT(taken, after.announcement.slices().size() / 2) << "most slices did not change";
  const auto missing = next.missing();
  ASSERT_FALSE(missing.empty()) << "the slices with the cabinet changed";
  for (int32_t k : missing)
    for (const auto& s : after.samples.at(k)) EXPECT_FALSE(next.accept(s));
  ASSERT_TRUE(next.complete());
  const MapFeatures back = next.build();
  ASSERT_EQ(back.slices.size(), changed.slices.size());
  for (size_t i = 0; i < back.slices.size(); ++i)
    EXPECT_EQ(cv::norm(back.slices[i].descriptors, changed.slices[i].descriptors, cv::NORM_HAMMING), 0);

  // The same map cut for another bandwidth budget is another version: a peer
  // must never combine parts of two chunkings.
  const MapOffer rechunked = makeOffer("alpha", changed, {}, 1000000, 600);
  bool parts_differ = false;
  for (const auto& [k, samples] : after.samples) parts_differ |= samples.size() != rechunked.samples.at(k).size();
  ASSERT_TRUE(parts_differ);
  EXPECT_NE(rechunked.announcement.version(), after.announcement.version());

  // Another agent's slices, or a different raster, are never taken.
  wire::MapAnnouncement other = after.announcement;
  other.agent("bravo");
  Reassembler stranger(other);
  EXPECT_EQ(stranger.adopt(old), 0u);
}

TEST(SliceCodec, TheReceiverRunsOrbWithTheAnnouncedSettings) {
  // An owner that keeps fewer features per slice than the default: the slices
  // that travel as occupancy must come out of the receiver's ORB the same.
  FeatureParams few;
  few.max_features = 200;
  few.fast_threshold = 30;
  SliceStack stack = sampleMap().occupancy;
  const MapFeatures owner = extractFeatures(stack, few);
  const MapOffer offer = makeOffer("alpha", owner, few, 1000000, 4000);
  EXPECT_EQ(featureParamsOf(offer.announcement).max_features, 200);
  EXPECT_EQ(featureParamsOf(offer.announcement).fast_threshold, 30);
  const MapFeatures back = receiveAll(offer, false).build();
  ASSERT_EQ(back.slices.size(), owner.slices.size());
  size_t fewer = 0;  // slices where the settings made a difference
  for (size_t i = 0; i < back.slices.size(); ++i) {
    ASSERT_EQ(back.slices[i].keypoints.size(), owner.slices[i].keypoints.size());
    EXPECT_EQ(cv::norm(back.slices[i].descriptors, owner.slices[i].descriptors, cv::NORM_HAMMING), 0);
    fewer += owner.slices[i].keypoints.size() < sampleMap().slices[i].keypoints.size();
  }
  EXPECT_GT(fewer, 0u) << "the default settings would have given other features";
  // The settings are part of the version: the same map described otherwise is another map.
  const MapOffer usual = makeOffer("alpha", sampleMap(), {}, 1000000, 4000);
  EXPECT_NE(usual.announcement.version(), offer.announcement.version());
}

TEST(SliceCodec, AMapOverTheMemoryBudgetIsRefusedBeforeAndWhileItArrives) {
  const MapOffer offer = makeOffer("alpha", sampleMap(), {}, 1000000, 4000);
  const size_t needs = announcedMemory(offer.announcement);
  EXPECT_EQ(fitsBudget(offer.announcement, needs - 1), Reject::OverBudget) << "refused before anything is allocated";
  EXPECT_FALSE(fitsBudget(offer.announcement, needs));

  // Fits as announced, but its occupancy inflates to cells the budget has no
  // room left for: the map is refused as the first such slice completes.
  size_t occupancy_slices = 0;
  for (const auto& [k, samples] : offer.samples)
    occupancy_slices += samples.front().encoding() == wire::SliceEncoding::OCCUPANCY;
  ASSERT_GT(occupancy_slices, 0u) << "a map this small travels as occupancy; slices " << offer.samples.size();
  Reassembler r(offer.announcement, needs);
  Rejection last;
  for (const auto& [k, samples] : offer.samples)
    for (const auto& s : samples)
      if (const auto why = r.accept(s)) last = why;
  EXPECT_EQ(last, Reject::OverBudget);
  EXPECT_TRUE(r.refused());
  EXPECT_FALSE(r.complete());
  EXPECT_EQ(r.accept(offer.samples.begin()->second.front()), Reject::OverBudget) << "every later sample too";

  Reassembler roomy(offer.announcement, needs * 100);
  for (const auto& [k, samples] : offer.samples)
    for (const auto& s : samples) EXPECT_FALSE(roomy.accept(s));
  EXPECT_TRUE(roomy.complete()) << "the same map within a budget that holds it";
}

TEST(SliceCodec, EveryFlowPeriodHoldsSeveralOfTheLargestSamples) {
  // The flow controller sends whole messages: a period that holds one and a
  // half of them sends one, and the stream runs at two thirds of its rate.
  for (const double kbps : {64.0, 250.0, 800.0, 1000.0, 10000.0})
    for (const size_t peers : {1, 2, 4, 6}) {
      TransportConfig c;
      c.bandwidth_kbps = kbps;
      c.peers.resize(peers);
      // A period holds eight of the largest messages, headers and all.
      const double per_period = static_cast<double>(flowBytesPerPeriod(c));
      EXPECT_GE(per_period, kSamplesPerPeriod * sampleDatagramBytes(kbps)) << kbps << " " << peers;
      EXPECT_GE(flowBaseMs(c), kFlowPeriodMs);
      EXPECT_EQ(flowPeriodMs(c), flowBaseMs(c) * static_cast<int>(peers));
      // Per period of every receiver, the stream's rate of payload (kbit/s):
      // what the daemon feeds the controller stays below what it lets out.
      const double payload = per_period * static_cast<double>(maxSampleBytes(kbps, false)) /
                             static_cast<double>(sampleDatagramBytes(kbps));
      EXPECT_NEAR(payload * 8 / flowPeriodMs(c), streamKbps(c), 0.01 * streamKbps(c));
    }
}
