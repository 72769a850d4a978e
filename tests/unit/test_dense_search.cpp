#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <tuple>

#include "core/candidates.hpp"
#include "core/dense_refine.hpp"
#include "core/dense_search.hpp"
#include "core/matcher.hpp"
#include "core/nearby_poses.hpp"
#include "core/pose_lander.hpp"
#include "core/voxel_filter.hpp"
#include "synth/synth.hpp"

using namespace tomomap;
using namespace tomomap::synth;

namespace {

constexpr double kGrid = 0.1;

/// One noiseless scan of a generated room, sliced at 0.1 m: about 30 slices.
Points roomScan() {
  SceneParams sp;
  sp.type = WorldType::Room;
  sp.seed = 3;
  return scanScene(makeScene(sp), noiseLevel("none"), 3).front().points;
}

SliceStack stackOf(const Points& p) { return makeSlices(voxelFilter(p, kGrid), kGrid); }

const ConsensusParams kSame{5 * kGrid, radians(10)};

/// `map` as the target and as the source moved by `moved`, described, and
/// the height offset in slices of the right pose.
struct MovedMaps {
  MapFeatures target, source;
  int right_offset = 0;
};
MovedMaps describedMoved(const Points& map, const Pose4& moved, const MatchParams& params) {
  const Points source = transformPoints(map, Pose4::fromMatrix(moved.matrix().inverse()));
  MovedMaps out{describeMap(map, params), describeMap(source, params)};
  const double z_between = out.target.occupancy.grid.z_min - out.source.occupancy.grid.z_min;
  out.right_offset = static_cast<int>(std::lround((moved.z - z_between) / params.grid));
  return out;
}

}  // namespace

// The room moved by a yaw past a quarter turn and a shift: a pose the search
// must find by itself, with no features and no starting guess.
TEST(DenseSearch, FindsARoomTurnedAndShiftedAndLeadsTheTurnsThatFitItsWalls) {
  const Points room = roomScan();
  const Pose4 moved{1.7, -2.3, 0.4, radians(117)};
  const Points source = transformPoints(room, Pose4::fromMatrix(moved.matrix().inverse()));
  const SliceStack t = stackOf(room), s = stackOf(source);
  ASSERT_TRUE(denseSearchable(t));

  const DenseSearch d = searchDensely(t, s, kSame, Eigen::Vector2d::Zero());
  ASSERT_TRUE(d.searched);
  ASSERT_GE(d.poses.size(), 2u);
  const DensePose& best = d.poses.front();
  // p_target = moved * p_source, so T = moved; z from the slice offset.
  const Eigen::Vector2d centre(s.grid.x_min + 0.5 * s.grid.width * kGrid, s.grid.y_min + 0.5 * s.grid.height * kGrid);
  const Eigen::Vector2d expected = planar(moved).apply(centre);
  EXPECT_LT((best.transform.apply(centre) - expected).norm(), 2 * kGrid);
  EXPECT_LT(std::abs(wrapAngle(best.transform.yaw - moved.yaw)), radians(2));
  EXPECT_NEAR(t.grid.z_min - s.grid.z_min + best.offset * kGrid, moved.z, kGrid);
  // The same room as itself: its telling cells land well ahead of any other
  // pose's (1.9x measured; the matcher asks for 1.3x).
  EXPECT_GT(static_cast<double>(best.telling_inliers), 1.6 * static_cast<double>(d.poses[1].telling_inliers));
  EXPECT_GT(best.support, t.size() / 2);
}

// The room is enclosed by its floor and ceiling: a pose that lands its
// furniture in its own open floor space contradicts what the other map saw
// there, and the right pose contradicts nothing.
TEST(DenseSearch, ChargesAPoseForCellsItLandsInSpaceTheOtherMapSawEmpty) {
  const SliceStack room = stackOf(roomScan());
  const DenseSearch d = searchDensely(room, room, kSame, Eigen::Vector2d::Zero());
  ASSERT_GE(d.poses.size(), 2u);
  const DensePose& best = d.poses.front();
  EXPECT_LT(best.transform.t.norm(), kGrid);
  EXPECT_EQ(best.offset, 0);
  for (const DensePose& p : d.poses) {
    std::cout << "yaw " << degrees(p.transform.yaw) << " deg, t " << p.transform.t.transpose() << ": "
              << p.telling_inliers << " telling cells landed, " << p.contradicted << " in empty space\n";
  }
  EXPECT_LT(best.contradicted * 50, best.telling_inliers);
  for (size_t k = 1; k < d.poses.size(); ++k)
    EXPECT_GT(d.poses[k].contradicted * 10, d.poses[k].telling_inliers) << "pose " << k;
}

// Finer than 0.1 m a noisy wall's cells leave the inlier radius and would
// read as empty: there the poses are ranked by telling cells alone.
TEST(DenseSearch, ReadsNoEmptySpaceOnCellsFinerThanAWallsNoise) {
  const Points scan = roomScan();
  const SliceStack fine = makeSlices(voxelFilter(scan, 0.05), 0.05);
  const DenseSearch d = searchDensely(fine, fine, kSame, Eigen::Vector2d::Zero());
  ASSERT_TRUE(d.searched);
  for (const DensePose& p : d.poses) EXPECT_EQ(p.contradicted, 0u);
}

TEST(DenseSearch, LeavesLargeAndIncompleteMapsAlone) {
  const SliceStack room = stackOf(roomScan());
  SliceStack wide = room;
  wide.grid.width = (kMaxCoarsening + 1) * DenseSearchParams{}.coarse_side + 1;
  EXPECT_FALSE(denseSearchable(wide));
  SliceStack partial = room;
  partial.partial = true;  // some slices came over the network as features
  EXPECT_FALSE(denseSearchable(partial));
  EXPECT_FALSE(searchDensely(room, partial, kSame, Eigen::Vector2d::Zero()).searched);
  EXPECT_FALSE(denseSearchable(SliceStack{}));
}

// A search on a lander prepared once for other work too (the candidates'
// landings) finds what a search on the two maps alone finds, pose for pose,
// with the wide search's coarser raster as well as the default one.
TEST(DenseSearch, ASearchOnALanderFindsWhatOneOnTheMapsFinds) {
  const Points room = roomScan();
  const Pose4 moved{1.2, 0.8, 0.2, radians(64)};
  const SliceStack t = stackOf(room), s = stackOf(transformPoints(room, Pose4::fromMatrix(moved.matrix().inverse())));
  DenseSearchParams wide;
  wide.coarse_side = kWideCoarseSide;
  wide.min_coarsening = kWideMinCoarsening;
  const PoseLander land(t, s);
  for (const DenseSearchParams& params : {DenseSearchParams{}, wide}) {
    const DenseSearch alone = searchDensely(t, s, kSame, s.grid.centre(), params),
                      shared = searchDensely(land, kSame, s.grid.centre(), params);
    ASSERT_TRUE(alone.searched);
    ASSERT_EQ(shared.poses.size(), alone.poses.size());
    for (size_t i = 0; i < alone.poses.size(); ++i) {
      EXPECT_EQ(shared.poses[i].transform.yaw, alone.poses[i].transform.yaw);
      EXPECT_EQ(shared.poses[i].transform.t, alone.poses[i].transform.t);
      EXPECT_EQ(shared.poses[i].offset, alone.poses[i].offset);
      EXPECT_EQ(shared.poses[i].score(), alone.poses[i].score());
    }
  }
}

// A pose found otherwise (the features' answer) is judged as the search judges
// its own: landing the search's poses again gives their very tally, and the
// half turn of a room on itself contradicts what the room saw empty.
TEST(DenseSearch, LandingAGivenPoseTalliesItAsTheSearchDoes) {
  const SliceStack room = stackOf(roomScan());
  const DenseSearch d = searchDensely(room, room, kSame, Eigen::Vector2d::Zero());
  ASSERT_FALSE(d.poses.empty());
  for (const DensePose& p : d.poses) {
    const DensePose again = landPose(room, room, p.transform, p.offset);
    EXPECT_EQ(again.inliers, p.inliers);
    EXPECT_EQ(again.telling_inliers, p.telling_inliers);
    EXPECT_EQ(again.contradicted, p.contradicted);
    EXPECT_EQ(again.support, p.support);
  }
  const DensePose itself = landPose(room, room, Rigid2D{}, 0);
  EXPECT_EQ(itself.contradicted, 0u);
  const Eigen::Vector2d centre(room.grid.x_min + 0.5 * room.grid.width * kGrid,
                               room.grid.y_min + 0.5 * room.grid.height * kGrid);
  Rigid2D half{kPi, Eigen::Vector2d::Zero()};
  half.t = centre - half.apply(centre);  // turned about the room's centre
  const DensePose turned = landPose(room, room, half, 0);
  EXPECT_GT(turned.contradicted, itself.contradicted + 100) << turned.telling_inliers << " telling";
}

// A room under a like storey 4 m above, a slab between that no scan saw: a
// pose of the room lands as much in empty space on either storey as on the
// room alone. The storey above does not enclose the room below: the heights
// between them, where the map saw nothing, were not seen through (else a
// pick between two like floors would read the lower one as contradicted).
TEST(DenseSearch, AStoreyAboveEnclosesNothingInTheOneBelow) {
  const SliceStack room = stackOf(roomScan());
  const int storey = static_cast<int>(std::lround(4.0 / kGrid));
  ASSERT_LT(room.size(), storey);
  SliceStack both = room;  // the room's very slices again, 4 m up, nothing seen between
  ASSERT_EQ(room.seen.size(), room.cells.size());
  both.cells.resize(static_cast<size_t>(storey));
  both.cells.insert(both.cells.end(), room.cells.begin(), room.cells.end());
  both.seen.resize(static_cast<size_t>(storey), false);
  both.seen.insert(both.seen.end(), room.seen.begin(), room.seen.end());
  const Eigen::Vector2d centre(room.grid.x_min + 0.5 * room.grid.width * kGrid,
                               room.grid.y_min + 0.5 * room.grid.height * kGrid);
  Rigid2D half{kPi, Eigen::Vector2d::Zero()};
  half.t = centre - half.apply(centre);  // turned about the room's centre
  const DensePose alone = landPose(room, room, half, 0);
  const DensePose below = landPose(both, room, half, 0), above = landPose(both, room, half, storey);
  std::cout << alone.contradicted << " cells in empty space on the room alone, " << below.contradicted
            << " on the storey below, " << above.contradicted << " on the storey above\n";
  ASSERT_GT(alone.contradicted, 100u);
  EXPECT_EQ(below.contradicted, alone.contradicted);
  EXPECT_EQ(above.contradicted, alone.contradicted);
}

// Two crops of one room sharing a fifth of it, at the right pose: a slice
// cannot land half of all its cells on the other crop (most lie where the
// other never looked), but it lands half of those that fall where the other
// saw anything: support_seen, what a slice holds over on a partial overlap
// (DensePose::support_seen).
TEST(DenseSearch, ASliceOfAPartialCropHoldsOnTheCellsThatLandWhereTheOtherMapSawAnything) {
  const Points room = roomScan();
  std::vector<float> xs;
  for (const auto& p : room) xs.push_back(p.x());
  std::sort(xs.begin(), xs.end());
  const float target_end = xs[xs.size() * 2 / 5], source_begin = xs[xs.size() / 5];
  Points near, far;
  for (const auto& p : room) {
    if (p.x() <= target_end) near.push_back(p);
    if (p.x() >= source_begin) far.push_back(p);
  }
  const SliceStack t = stackOf(near), s = stackOf(far);
  const int offset = static_cast<int>(std::lround((s.grid.z_min - t.grid.z_min) / kGrid));
  const DensePose right = landPose(t, s, Rigid2D{}, offset);
  std::cout << s.size() << " source slices; the right pose holds over " << right.support << " counting every cell, "
            << right.support_seen << " counting those landing where the target saw anything\n";
  EXPECT_LT(right.support, s.size() / 4) << "of all its cells";
  EXPECT_GT(right.support_seen, s.size() / 2) << "of those landing where the other crop saw anything";
  const DensePose apart = landPose(t, s, Rigid2D{0.0, Eigen::Vector2d(0.0, 1.5)}, offset);
  std::cout << "a pose 1.5 m off: " << apart.support_seen << "\n";
  EXPECT_LT(apart.support_seen, right.support_seen / 2) << "a pose 1.5 m off";
}

// A pose a few cells and degrees off the right one, as a dense search's coarse
// cell or a feature answer on a few keypoints leaves it, climbs back: the room
// landed on itself is found again within a cell and a yaw step, landing more.
TEST(DenseSearch, APoseOffTheRightOneClimbsUphillToIt) {
  const SliceStack room = stackOf(roomScan());
  DenseSearchParams two_threads;
  two_threads.threads = 2;
  const Rigid2D off{radians(4), {0.4, -0.3}};
  const DensePose start = landPose(room, room, off, 1), top = uphill(room, room, off, 1, two_threads);
  EXPECT_GT(top.score(), start.score());
  EXPECT_EQ(top.offset, 0);
  EXPECT_LT(top.transform.t.norm(), 1.5 * kGrid);
  EXPECT_LT(std::abs(top.transform.yaw), radians(1));
  EXPECT_GE(top.score(), landPose(room, room, Rigid2D{}, 0).score());
}

// A pose's landing slice by slice adds up to its tallies: on itself a room
// lands every one of its cells and contradicts none; moved, its slices' cells
// on the target add up to the pose's inliers.
TEST(DenseSearch, APosesSlicesAddUpToItsTallies) {
  const SliceStack room = stackOf(roomScan());
  size_t cells = 0;
  for (const auto& slice : room.cells) cells += slice.size();
  const Rigid2D moved{radians(4), {0.4, -0.3}};
  const auto slices = landSlices(room, room, {{Rigid2D{}, 0}, {moved, 1}});
  ASSERT_EQ(slices.size(), 2u);
  const auto sum = [](const std::vector<SliceLanding>& s, uint32_t SliceLanding::*count) {
    size_t n = 0;
    for (const SliceLanding& l : s) n += l.*count;
    return n;
  };
  EXPECT_EQ(sum(slices[0], &SliceLanding::cells), cells);
  EXPECT_EQ(sum(slices[0], &SliceLanding::on), cells);
  EXPECT_EQ(sum(slices[0], &SliceLanding::seen), cells);
  EXPECT_EQ(sum(slices[0], &SliceLanding::contradicted), 0u);
  EXPECT_GT(sum(slices[0], &SliceLanding::telling), 0u);
  EXPECT_EQ(sum(slices[0], &SliceLanding::telling_on), sum(slices[0], &SliceLanding::telling));
  EXPECT_EQ(sum(slices[1], &SliceLanding::cells), cells);
  const DensePose pose = landPose(room, room, moved, 1);
  EXPECT_EQ(sum(slices[1], &SliceLanding::on), pose.inliers);
  EXPECT_LT(sum(slices[1], &SliceLanding::on), cells * 3 / 4) << "moved, fewer land";
  // Slice by slice: the slices holding half their cells, or half of those
  // landing where the target saw anything, are the pose's support.
  int holding = 0, holding_seen = 0;
  for (const SliceLanding& l : slices[1]) {
    holding += l.on > 0 && 2 * l.on >= l.cells;
    holding_seen += l.seen > 0 && 2 * l.on >= l.seen;
  }
  EXPECT_EQ(holding, pose.support);
  EXPECT_EQ(holding_seen, pose.support_seen);
  EXPECT_GT(pose.support, 0);
  EXPECT_LT(pose.support, room.size());
}

// A climb keeps what it counted and landed in a memo: a step in height asks
// again for the same transforms and most of the same poses. Through the memo
// the scores are the same to the bit as counted afresh, whatever the memo
// held before; a memo handed to another lander starts over.
TEST(DenseSearch, ScoresThroughAMemoAreTheScoresCountedAfresh) {
  const SliceStack room = stackOf(roomScan());
  DenseSearchParams two_threads;
  two_threads.threads = 2;
  const PoseLander land(room, room, two_threads);
  const auto ring = [](const Rigid2D& T, int offset) {
    PoseLander::Poses out;
    for (int o = offset - 1; o <= offset + 1; ++o)
      for (const Rigid2D& step : {T, Rigid2D{T.yaw, T.t + Eigen::Vector2d(0.1, 0)}, Rigid2D{T.yaw + 0.01, T.t}})
        out.emplace_back(step, o);
    return out;
  };
  const Rigid2D T{radians(4), {0.4, -0.3}};
  PoseLander::Memo memo;
  // The same transforms a height up, then down again (every pose known), then elsewhere.
  for (const PoseLander::Poses& poses : {ring(T, 0), ring(T, 1), ring(T, 0), ring(Rigid2D{}, 0)}) {
    const std::vector<double> remembered = land.scores(poses, &memo), afresh = land.scores(poses);
    ASSERT_EQ(remembered.size(), poses.size());
    for (size_t n = 0; n < poses.size(); ++n) EXPECT_EQ(remembered[n], afresh[n]) << n;
  }
  // Another lander of other maps: the memo's counts are not its own.
  SliceStack moved = room;
  moved.cells.erase(moved.cells.begin());
  const PoseLander other(room, moved, two_threads);
  const PoseLander::Poses poses = ring(T, 0);
  const std::vector<double> there = other.scores(poses, &memo), afresh = other.scores(poses);
  for (size_t n = 0; n < poses.size(); ++n) EXPECT_EQ(there[n], afresh[n]) << n;
  EXPECT_NE(there, land.scores(poses));  // not the first lander's counts
}

// A climb ranks its steps by score alone, counted on the telling cells alone,
// and lands only where it stops: the scores are the landed poses' own, at
// every height and at poses repeated in one call (one landing per transform).
TEST(DenseSearch, ScoresAloneAreTheLandedPosesScores) {
  const SliceStack room = stackOf(roomScan());
  DenseSearchParams two_threads;
  two_threads.threads = 2;
  const PoseLander land(room, room, two_threads);
  PoseLander::Poses poses;
  for (const Rigid2D& T : {Rigid2D{}, Rigid2D{radians(4), {0.4, -0.3}}, Rigid2D{radians(180), {1.0, 0.5}}})
    for (int offset : {-1, 0, 1, 0}) poses.emplace_back(T, offset);
  const std::vector<DensePose> landed = land(poses);
  const std::vector<double> scores = land.scores(poses);
  ASSERT_EQ(landed.size(), poses.size());
  ASSERT_EQ(scores.size(), poses.size());
  for (size_t n = 0; n < poses.size(); ++n) {
    SCOPED_TRACE(n);
    // Landed with the others, each pose is landed as it is alone.
    const DensePose alone = landPose(room, room, poses[n].first, poses[n].second);
    EXPECT_EQ(landed[n].transform.yaw, poses[n].first.yaw);
    EXPECT_EQ(landed[n].transform.t, poses[n].first.t);
    EXPECT_EQ(landed[n].offset, poses[n].second);
    EXPECT_EQ(landed[n].inliers, alone.inliers);
    EXPECT_EQ(landed[n].telling_inliers, alone.telling_inliers);
    EXPECT_EQ(landed[n].contradicted, alone.contradicted);
    EXPECT_EQ(landed[n].support, alone.support);
    EXPECT_EQ(landed[n].support_seen, alone.support_seen);
    EXPECT_EQ(scores[n], landed[n].score());
  }
  EXPECT_GT(scores[1], scores[5]);  // the room on itself lands more than off it
  EXPECT_TRUE(land.scores({}).empty());
  // Slice by slice, and the occupancy's height, the same from the lander
  // (its two maps prepared on two threads) as each prepared for one call.
  const auto slices = land.slices(poses), alone = landSlices(room, room, poses);
  ASSERT_EQ(slices.size(), poses.size());
  ASSERT_EQ(alone.size(), poses.size());
  for (size_t n = 0; n < poses.size(); ++n) {
    SCOPED_TRACE(n);
    ASSERT_EQ(slices[n].size(), alone[n].size());
    for (size_t k = 0; k < slices[n].size(); ++k) {
      const SliceLanding &a = slices[n][k], &b = alone[n][k];
      EXPECT_EQ(std::tie(a.slice, a.cells, a.telling, a.seen, a.on, a.telling_on, a.contradicted),
                std::tie(b.slice, b.cells, b.telling, b.seen, b.on, b.telling_on, b.contradicted));
    }
    EXPECT_EQ(land.heightOffset(poses[n].first, poses[n].second, 5),
              occupancyHeightOffset(room, room, poses[n].first, poses[n].second, 5));
  }
  // Some source slices came over the network as features, without cells:
  // those land nothing, and the rest land their cells as on the whole map
  // (which of them are telling reads the slices around them, some missing).
  SliceStack partial = room;
  partial.partial = true;
  for (size_t k = 0; k < partial.cells.size(); k += 3) partial.cells[k].clear();
  const auto in_part = PoseLander(room, partial).slices(poses);
  ASSERT_EQ(in_part.size(), poses.size());
  for (size_t n = 0; n < poses.size(); ++n) {
    SCOPED_TRACE(n);
    size_t compared = 0;
    for (const SliceLanding& a : in_part[n]) {
      if (a.slice % 3 == 0) {
        EXPECT_EQ(a.cells, 0u) << "slice " << a.slice;
        continue;
      }
      for (const SliceLanding& b : slices[n])
        if (b.slice == a.slice) {
          ++compared;
          EXPECT_EQ(std::tie(a.cells, a.seen, a.on), std::tie(b.cells, b.seen, b.on)) << "slice " << a.slice;
        }
    }
    EXPECT_GT(compared, 0u);
  }
  EXPECT_FALSE(denseSearchable(partial)) << "a partial stack is not searched";
}

// The height the occupancy gives a pose: where most of the source's cells
// land, the offset asked about where it is among the most, else the first
// of them; offsets with no target slice there land nothing.
TEST(DenseSearch, TheOccupancysHeightIsWhereMostCellsLandTheOneAskedAboutOnATie) {
  const SliceStack room = stackOf(roomScan());
  const auto fullest = std::max_element(room.cells.begin(), room.cells.end(),
                                        [](const auto& a, const auto& b) { return a.size() < b.size(); });
  SliceStack one = room, five = room, gaps = room;
  one.cells = {*fullest};
  five.cells.assign(5, *fullest);                 // the same slice at heights 0-4: every offset 0-4 lands alike
  gaps.cells = {{}, *fullest, *fullest, {}, {}};  // only offsets 1 and 2 land anything
  EXPECT_EQ(occupancyHeightOffset(five, one, Rigid2D{}, 2, 2), 2);
  EXPECT_EQ(occupancyHeightOffset(five, one, Rigid2D{}, 1, 3), 1);
  EXPECT_EQ(occupancyHeightOffset(five, one, Rigid2D{}, -3, 1), -3);  // nothing lands: the offset asked about
  EXPECT_EQ(occupancyHeightOffset(gaps, one, Rigid2D{}, 3, 3), 1);
  EXPECT_EQ(occupancyHeightOffset(gaps, one, Rigid2D{}, 2, 1), 2);
}

// Two proposals of the right pose at wrong heights are one place: only the
// one that lands more climbs. Both are judged at the height where most of
// the source's occupancy lands (a climb weighs the telling cells alone, and
// a room's floor and ceiling are not telling), the right one.
TEST(Candidates, AreJudgedAtTheHeightWhereTheOccupancyLandsMost) {
  const Points room = roomScan();
  const Pose4 moved{1.1, -0.6, 0.4, radians(35)};
  MatchParams params;
  params.grid = kGrid;
  const auto [t, s, right] = describedMoved(room, moved, params);
  ASSERT_TRUE(denseSearchable(t.occupancy));
  const std::vector<Proposal> proposals{{Candidate::From::features, 0, 0, planar(moved), right + 2},
                                        {Candidate::From::feature_rival, 1, 0, planar(moved), right - 3}};
  const std::vector<Candidate> candidates = refineAndLand(t, s, proposals, params);
  ASSERT_EQ(candidates.size(), 2u);
  for (const Candidate& c : candidates) {
    SCOPED_TRACE(fromName(c.from));
    EXPECT_NEAR(c.landed.offset, right, 1);
  }
}

// A map too large for a dense search (the room and a copy of it turned a
// quarter and 25 m along: 35 m across) and a proposal a few cells and a
// degree off the right pose, as a feature answer on a few keypoints leaves
// it: the candidate is judged, and would be answered, within a cell of the
// right pose, landing more than as proposed.
TEST(Candidates, OnAMapTooLargeForADenseSearchAreRefinedOntoTheOccupancy) {
  Points map = roomScan();
  const Points copy = transformPoints(roomScan(), Pose4{25.0, 3.0, 0.0, radians(90)});
  map.insert(map.end(), copy.begin(), copy.end());
  const Pose4 moved{1.1, -0.6, 0.0, radians(35)};
  MatchParams params;
  params.grid = kGrid;
  const auto [t, s, right] = describedMoved(map, moved, params);
  ASSERT_FALSE(denseSearchable(t.occupancy));
  const Eigen::Vector2d centre = s.occupancy.grid.centre();
  // The right pose turned a degree about the source's centre and shifted 0.2 m.
  Rigid2D off = planar(moved);
  off.yaw += radians(1);
  off.t = planar(moved).apply(centre) + Eigen::Vector2d(0.2, -0.1) -
          Rigid2D{off.yaw, Eigen::Vector2d::Zero()}.apply(centre);
  const std::vector<Candidate> candidates =
      refineAndLand(t, s, {{Candidate::From::features, 0, 0, off, right}}, params);
  ASSERT_EQ(candidates.size(), 1u);
  const Candidate& c = candidates.front();
  EXPECT_GT(c.landed.score(), c.proposed_landed.score());
  EXPECT_LT((c.landed.transform.apply(centre) - planar(moved).apply(centre)).norm(), kGrid);
  EXPECT_LT(std::abs(wrapAngle(c.landed.transform.yaw - moved.yaw)), radians(0.2));
}

// The room on itself, started a few hundredths of a metre and a few
// milliradians off: ICP on the occupied cells brings it back within a tenth
// of a cell.
TEST(DenseRefine, BringsARoomBackOntoItself) {
  const SliceStack room = stackOf(roomScan());
  const Rigid2D back = refineOnOccupancy(room, room, 0, Rigid2D{0.004, {0.03, -0.04}}).transform;
  EXPECT_LT(back.t.norm(), 0.1 * kGrid);
  EXPECT_LT(std::abs(back.yaw), 0.001);
}

// One refiner, its target prepared once, refines several starts at several
// heights to the very transforms that a refinement each gives: nothing of
// one call stays for the next.
TEST(DenseRefine, OnePreparationServesManyPosesAlike) {
  const SliceStack room = stackOf(roomScan());
  const OccupancyRefiner refine(room, room);
  for (const Rigid2D& start : {Rigid2D{0.004, {0.03, -0.04}}, Rigid2D{-0.01, {0.1, 0.05}}, Rigid2D{}})
    for (int offset : {0, 1, -1}) {
      const Rigid2D once = refineOnOccupancy(room, room, offset, start).transform;
      const Rigid2D reused = refine(offset, start).transform;
      EXPECT_EQ(reused.yaw, once.yaw);
      EXPECT_EQ(reused.t, once.t);
    }
}
