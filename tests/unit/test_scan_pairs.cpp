// Pairs cut from one scan: the crops share what was drawn, the degraded crop is
// degraded, and the ground truth undoes the source's move.
#include <gtest/gtest.h>

#include <set>
#include <tuple>

#include "synth/scan_pairs.hpp"

using namespace tomomap;
using namespace tomomap::synth;

namespace {

/// A room map stands in for a scan: any cloud of points will do.
Points roomScan() {
  SceneParams sp;
  sp.type = WorldType::Room;
  sp.seed = 5;
  return scanScene(makeScene(sp), noiseLevel("none"), 5)[0].points;
}

using Key = std::tuple<long, long, long>;
Key keyOf(const Eigen::Vector3f& p) {  // to a tenth of a millimetre: the move and its inverse round-trip within it
  return {std::lround(p.x() * 1e4), std::lround(p.y() * 1e4), std::lround(p.z() * 1e4)};
}

}  // namespace

TEST(ScanPairs, TheCropsShareTheDrawnOverlapAndTheGroundTruthUndoesTheMove) {
  const Points scan = roomScan();
  for (uint64_t seed : {1, 3, 5}) {  // odd seeds thin one crop, so its kept points are exact copies
    const ScanPair pair = makeScanPair(scan, {seed});
    const ScanPairInfo& info = pair.info;
    ASSERT_GE(info.overlap, 0.2);
    ASSERT_LE(info.overlap, 0.6);
    ASSERT_GE(info.thinning, 3);
    ASSERT_LE(info.thinning, 10);
    std::set<Key> target;
    for (const auto& p : pair.target.points) target.insert(keyOf(p));
    // T_target_source = pose_target * pose_source^-1 (synth's convention) takes
    // the source back into the scan's frame, where the shared points coincide.
    const Pose4 T = Pose4::fromMatrix(pair.target.pose * pair.source.pose.inverse());
    size_t shared = 0;
    for (const auto& p : pair.source.points) shared += target.count(keyOf(T.apply(p)));
    // Of the source's points, `overlap` lie in the band the target covers too;
    // a thinned target holds one in `thinning` of them.
    const double expected = info.target_degraded ? info.overlap / info.thinning : info.overlap;
    EXPECT_NEAR(static_cast<double>(shared) / static_cast<double>(pair.source.points.size()), expected, 0.05)
        << "seed " << seed << ": " << describe(info);
    const size_t degraded = info.target_degraded ? pair.target.points.size() : pair.source.points.size();
    const size_t whole = info.target_degraded ? pair.source.points.size() : pair.target.points.size();
    EXPECT_LT(degraded, whole) << "the thinned crop is the sparser one";
  }
}

TEST(ScanPairs, EvenSeedsAddNoiseInsteadAndEverySeedIsItsOwnPair) {
  const Points scan = roomScan();
  const ScanPair even = makeScanPair(scan, {2});
  EXPECT_EQ(even.info.thinning, 1);
  EXPECT_DOUBLE_EQ(even.info.noise, 0.02);
  const ScanPair again = makeScanPair(scan, {2});
  EXPECT_EQ(again.source.points, even.source.points) << "deterministic from the seed";
  const ScanPair other = makeScanPair(scan, {4});
  EXPECT_NE(other.info.move.x, even.info.move.x);
  EXPECT_NE(describe(other.info), "");
}

TEST(ScanPairs, AScanTooSmallToCutIsAnInputError) {
  Points few(500, Eigen::Vector3f(1, 2, 3));
  EXPECT_THROW(makeScanPair(few, {1}), InputError);
}
