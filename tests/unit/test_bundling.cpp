// Small pieces of slices riding in other samples' spare room: every part is
// written once, no sample grows past the sample size, and a receiver puts the
// map together from the samples in any order.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

#include "core/matcher.hpp"
#include "support.hpp"
#include "synth/synth.hpp"
#include "transport/bundling.hpp"
#include "transport/map_offer.hpp"
#include "transport/participant.hpp"
#include "transport/reassembler.hpp"

using namespace tomomap;
using namespace tomomap::transport;

namespace {

/// A generated room described at g = 0.05 (as the link tests' agents do), offered for a 1 Mbit/s budget.
struct Offered {
  Points points;
  MapFeatures features;
  size_t sample_bytes = maxSampleBytes(1000, /*secure=*/false);
  MapOffer offer;
};

MatchParams atFiveCentimetres() {
  MatchParams p;
  p.grid = 0.05;
  return p;
}

const Offered& offered() {
  static const Offered o = [] {
    synth::SceneParams sp;
    sp.scale = 0.5;
    const synth::Scene scene = synth::makeScene(sp);
    Offered x;
    x.points = synth::scanScene(scene, synth::noiseLevel("low"), 1).front().points;
    x.features = describeMap(x.points, atFiveCentimetres());
    x.offer = makeOffer("alpha", x.features, {}, 1000000, x.sample_bytes);
    return x;
  }();
  return o;
}

using PieceId = std::pair<int, int>;  // slice, part

}  // namespace

TEST(Bundling, EveryPartIsWrittenOnceInFewerSamplesWithinTheSampleSize) {
  const Offered& o = offered();
  std::map<PieceId, wire::SliceFeatures> parts;
  for (const auto& [k, samples] : o.offer.samples)
    for (const auto& s : samples) parts[{s.slice(), s.part()}] = s;

  std::map<PieceId, int> written;
  for (const auto& b : o.offer.bundles) {
    EXPECT_LE(wire::SliceFeatures::getCdrSerializedSize(b), o.sample_bytes);
    for (const auto& piece : unbundle(wire::SliceFeatures(b))) {
      const PieceId id{piece.slice(), piece.part()};
      ++written[id];
      ASSERT_TRUE(parts.count(id)) << "slice " << id.first << " part " << id.second;
      EXPECT_EQ(piece, parts.at(id)) << "slice " << id.first << " part " << id.second;
    }
  }
  EXPECT_EQ(written.size(), parts.size());
  for (const auto& [id, times] : written) EXPECT_EQ(times, 1) << "slice " << id.first << " part " << id.second;
  // Nearly half the room's parts are smaller than a sample (a slice's last
  // part, or a slice that fits one): alone, each would pay a datagram's
  // headers to every receiver.
  EXPECT_LT(static_cast<double>(o.offer.bundles.size()), 0.85 * static_cast<double>(parts.size()))
      << o.offer.bundles.size() << " samples for " << parts.size() << " parts";
}

TEST(Bundling, EachSliceNamesTheSamplesThatCarryIt) {
  const Offered& o = offered();
  ASSERT_EQ(o.offer.bundles_of.size(), o.offer.announcement.slices().size());
  for (const auto& e : o.offer.announcement.slices()) {
    std::set<int> parts;
    for (size_t b : o.offer.bundles_of.at(e.slice()))
      for (const auto& piece : unbundle(wire::SliceFeatures(o.offer.bundles.at(b))))
        if (piece.slice() == e.slice()) parts.insert(piece.part());
    EXPECT_EQ(parts.size(), e.parts()) << "slice " << e.slice();
  }
}

TEST(Bundling, AReceiverPutsTheMapTogetherFromTheSamplesInAnyOrder) {
  const Offered& o = offered();
  std::vector<wire::SliceFeatures> wire = o.offer.bundles;
  std::shuffle(wire.begin(), wire.end(), std::mt19937(11));
  Reassembler r(o.offer.announcement);
  for (auto& s : wire)
    for (const auto& piece : unbundle(std::move(s))) EXPECT_FALSE(r.accept(piece)) << r.accept(piece).text();
  ASSERT_TRUE(r.complete());
  EXPECT_EQ(r.build().featureCount(), o.features.featureCount());
}

TEST(Bundling, RidersSpeakForTheAgentAndVersionOfTheirSample) {
  // A rider has no agent or version of its own: a peer cannot slip a piece
  // of another agent's map into its own sample.
  wire::SliceFeatures host;
  host.agent("bravo");
  host.version(7);
  host.slice(1);
  wire::SlicePiece rider;
  rider.slice(2);
  rider.parts(1);
  rider.occupancy({1, 2, 3});
  host.riders().push_back(rider);
  const auto pieces = unbundle(std::move(host));
  ASSERT_EQ(pieces.size(), 2u);
  for (const auto& p : pieces) {
    EXPECT_EQ(p.agent().to_string(), "bravo");
    EXPECT_EQ(p.version(), 7u);
    EXPECT_TRUE(p.riders().empty());
  }
  EXPECT_EQ(pieces[1].slice(), 2);
  EXPECT_EQ(pieces[1].occupancy(), (std::vector<uint8_t>{1, 2, 3}));
}

TEST(Bundling, APieceOverTheRiderBoundsTravelsAlone) {
  std::vector<wire::SliceFeatures> pieces(2);
  pieces[0].slice(0);
  pieces[1].slice(1);
  pieces[1].occupancy(std::vector<uint8_t>(wire::MAX_RIDER_OCCUPANCY + 1, 0));
  const Bundles b = bundle(pieces, 1 << 20);
  EXPECT_EQ(b.samples.size(), 2u);
  EXPECT_EQ(b.home, (std::vector<size_t>{0, 1}));
}

TEST(Bundling, AfterAMapUpdateTheSamplesOfChangedSlicesCarryNoKeptOne) {
  // The robot maps a cabinet: peers holding the first version ask for the
  // changed slices only, and get no kept slice along with them.
  const Offered& o = offered();
  MapOffer after = makeOffer("alpha", describeMap(tomomap::test::withCabinet(o.points), atFiveCentimetres()), {},
                             1000000, o.sample_bytes);
  bundleOffer(after, &o.offer.announcement);
  const std::set<int> kept = unchangedSlices(after.announcement, o.offer.announcement);
  ASSERT_GT(kept.size(), 0u);
  ASSERT_LT(kept.size(), after.announcement.slices().size()) << "the cabinet changed some slices";
  size_t changed_bytes = 0, all_bytes = 0;
  for (const auto& b : after.bundles) {
    const auto pieces = unbundle(wire::SliceFeatures(b));
    const bool host_kept = kept.count(pieces.front().slice()) > 0;
    for (const auto& p : pieces) EXPECT_EQ(kept.count(p.slice()) > 0, host_kept) << "slice " << p.slice();
    const size_t bytes = wire::SliceFeatures::getCdrSerializedSize(b);
    all_bytes += bytes;
    if (!host_kept) changed_bytes += bytes;
  }
  EXPECT_LT(changed_bytes, all_bytes);
  std::printf("%zu of %zu slices changed: %zu of %zu bytes to send again\n",
              after.announcement.slices().size() - kept.size(), after.announcement.slices().size(), changed_bytes,
              all_bytes);
}
