#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <tuple>

#include "core/slices.hpp"

using namespace tomomap;

TEST(Slices, EveryPointLandsInExactlyOneSlice) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-5.f, 5.f);
  SliceGrid g;
  g.cell = 0.05;
  g.z_min = -5.0;
  for (int i = 0; i < 100000; ++i) {
    const double z = u(rng);
    int owners = 0;
    for (int k = g.sliceIndex(z) - 2; k <= g.sliceIndex(z) + 2; ++k)
      owners += (g.sliceHeight(k) - g.cell / 2 < z && z <= g.sliceHeight(k) + g.cell / 2);
    ASSERT_EQ(owners, 1) << "z = " << z;
    const int k = g.sliceIndex(z);
    ASSERT_GT(z, g.sliceHeight(k) - g.cell / 2 - 1e-9);
    ASSERT_LE(z, g.sliceHeight(k) + g.cell / 2 + 1e-9);
  }
}

TEST(Slices, BoundaryBelongsToTheLowerSlice) {
  SliceGrid g;
  g.cell = 0.5;  // exactly representable, so the boundary is exact
  g.z_min = 0.0;
  EXPECT_EQ(g.sliceIndex(0.25), 0);       // h_0 + g/2 is in slice 0 ...
  EXPECT_EQ(g.sliceIndex(0.2500001), 1);  // ... and just above it is slice 1
  EXPECT_EQ(g.sliceIndex(-0.25), -1);
}

/// A box-shaped room: floor, four walls, ceiling, sampled every `step`.
static Points room(double step) {
  Points p;
  for (double x = 0; x <= 4; x += step)
    for (double y = 0; y <= 3; y += step) {
      p.emplace_back(x, y, 0);
      p.emplace_back(x, y, 2.5);
    }
  for (double z = 0; z <= 2.5; z += step) {
    for (double x = 0; x <= 4; x += step) {
      p.emplace_back(x, 0, z);
      p.emplace_back(x, 3, z);
    }
    for (double y = 0; y <= 3; y += step) {
      p.emplace_back(0, y, z);
      p.emplace_back(4, y, z);
    }
  }
  return p;
}

TEST(Slices, StackCoversTheMapAndKeepsAllOccupiedCells) {
  const Points pts = room(0.05);
  const SliceStack s = makeSlices(pts, 0.1);
  EXPECT_EQ(s.grid.width, 41);
  EXPECT_EQ(s.grid.height, 31);
  EXPECT_EQ(s.size(), 26);  // 0 .. 2.5 m in 0.1 m steps
  // Wall slices hold the room's outline: 2 * (41 + 31) - 4 cells, more than width + height.
  EXPECT_EQ(s.cells[10].size(), 2u * (41 + 31) - 4);
  EXPECT_EQ(cv::countNonZero(s.image(10)), static_cast<int>(s.cells[10].size()));
  EXPECT_EQ(s.image(10, 5).cols, 41 + 10);
}

TEST(Slices, SparseSlicesAreEmptiedAndEndsTrimmed) {
  Points pts = room(0.05);
  pts.emplace_back(1.0f, 1.0f, 4.0f);  // a lone point far above: too sparse to describe
  const SliceStack s = makeSlices(pts, 0.1);
  EXPECT_EQ(s.size(), 26);  // the lone point's slice was trimmed away with the gap
}

// Two short rails above the room's ceiling: a third of the raster's width +
// height in cells, a slice the stack keeps (kSparsestSlice) and its full
// slices leave out (kFullSlice); the room's outline slices are in both, at
// the same heights.
TEST(Slices, ASparseSliceIsKeptButNotAmongTheFullSlices) {
  Points pts = room(0.05);
  for (double x = 0; x <= 1.2; x += 0.05) pts.emplace_back(x, 1.5, 3.4);
  for (double x = 0; x <= 1.2; x += 0.05) pts.emplace_back(x, 1.7, 3.4);
  const SliceStack s = makeSlices(pts, 0.1);
  ASSERT_EQ(s.size(), 35);
  const double outline = s.grid.width + s.grid.height;
  EXPECT_GE(s.cells[34].size(), kSparsestSlice * outline);
  EXPECT_LT(s.cells[34].size(), kFullSlice * outline);
  EXPECT_TRUE(s.cells[30].empty());  // between: nothing
  // Without it, the rails' slice and the empty ones below it are trimmed away,
  // as slicing at that bar trims them.
  const SliceStack full = fullSlices(s), at_full_bar = makeSlices(pts, 0.1, 0, nullptr, kFullSlice);
  EXPECT_EQ(full.size(), 26);
  EXPECT_EQ(full.grid, at_full_bar.grid);
  EXPECT_EQ(full.cells, at_full_bar.cells);
  EXPECT_EQ(full.cells[10], s.cells[10]);
}

// A height where the map had no point was not seen (a slab between two
// floors); one with too few points to describe was: the empty space a pose
// is judged on reads the difference (enclosure.hpp). Slicing,
// pooling and keeping the full slices carry it along.
TEST(Slices, AHeightWithNoPointIsUnseenWhereASparseOneIsSeen) {
  Points pts = room(0.05);
  for (double x = 0; x <= 1.2; x += 0.05) pts.emplace_back(x, 1.5, 3.4);  // rails, as above
  for (double x = 0; x <= 1.2; x += 0.05) pts.emplace_back(x, 1.7, 3.4);
  pts.emplace_back(1.0f, 1.0f, 3.0f);   // a lone point: too sparse to describe
  pts.emplace_back(1.0f, 1.0f, -0.5f);  // another below the floor, trimmed away with the heights between
  const SliceStack s = makeSlices(pts, 0.1);
  ASSERT_EQ(s.size(), 35);
  EXPECT_NEAR(s.grid.z_min, 0.0, 1e-6);
  std::vector<bool> expected(35, false);  // the room to its ceiling, the lone point and the rails
  for (int k = 0; k <= 25; ++k) expected[static_cast<size_t>(k)] = true;
  expected[30] = expected[34] = true;
  EXPECT_EQ(s.seen, expected);
  EXPECT_TRUE(s.cells[30].empty()) << "seen, not described";
  const std::vector<SliceRun> runs = seenRuns(s);  // the same, as runs
  ASSERT_EQ(runs.size(), 5u);
  const std::vector<std::tuple<int, int, bool>> expected_runs = {
      {0, 25, true}, {26, 29, false}, {30, 30, true}, {31, 33, false}, {34, 34, true}};
  for (size_t i = 0; i < runs.size(); ++i)
    EXPECT_EQ(std::tuple(runs[i].first, runs[i].last, runs[i].seen), expected_runs[i]) << "run " << i;
  SliceStack unsaid = s;  // a stack that does not say: every slice seen
  unsaid.seen.clear();
  ASSERT_EQ(seenRuns(unsaid).size(), 1u);
  EXPECT_EQ(std::tuple(seenRuns(unsaid)[0].first, seenRuns(unsaid)[0].last), std::tuple(0, 34));
  EXPECT_TRUE(seenRuns(SliceStack{}).empty());
  const SliceStack p = pooled(s);
  ASSERT_EQ(p.seen.size(), p.cells.size());
  EXPECT_TRUE(p.seen[15]);   // fine slices 30 and 31
  EXPECT_FALSE(p.seen[14]);  // 28 and 29
  const SliceStack full = fullSlices(s);
  ASSERT_EQ(full.size(), 26);
  EXPECT_EQ(full.seen, std::vector<bool>(26, true));
}

TEST(Slices, TooFineGridFailsLoudly) {
  const Points pts{{0, 0, 0}, {1000, 1000, 1}};
  EXPECT_THROW(makeSlices(pts, 0.01), InputError);
}

TEST(Slices, EmptyMapGivesEmptyStack) { EXPECT_EQ(makeSlices({}, 0.1).size(), 0); }

TEST(Slices, PoolingKeepsEveryOccupiedCellAtTwiceTheCell) {
  const SliceStack fine = makeSlices(room(0.05), 0.05);
  const SliceStack p = pooled(fine);
  EXPECT_DOUBLE_EQ(p.grid.cell, 0.1);
  EXPECT_EQ(p.size(), (fine.size() + 1) / 2);
  EXPECT_EQ(p.grid.width, (fine.grid.width + 1) / 2);
  EXPECT_EQ(p.grid.height, (fine.grid.height + 1) / 2);
  // Pooled slice k sits midway between fine slices 2k and 2k + 1.
  EXPECT_NEAR(p.grid.sliceHeight(3), 0.5 * (fine.grid.sliceHeight(6) + fine.grid.sliceHeight(7)), 1e-9);
  for (int k = 0; k < fine.size(); ++k)
    for (uint32_t idx : fine.cells[static_cast<size_t>(k)]) {
      const Eigen::Vector2d c = fine.grid.cellCentre(idx);
      const Eigen::Vector2d at = p.grid.toPixel(c.x(), c.y());  // a fine centre is a quarter cell off a pooled one
      const auto pooled_idx = static_cast<uint32_t>(std::lround(at.y()) * p.grid.width + std::lround(at.x()));
      const auto& cells = p.cells[static_cast<size_t>(k / 2)];
      ASSERT_TRUE(std::binary_search(cells.begin(), cells.end(), pooled_idx)) << "slice " << k << " cell " << idx;
    }
  // No cell is made up: a wall slice still holds the room's outline alone.
  EXPECT_EQ(p.cells[10].size(), 2u * static_cast<size_t>(p.grid.width + p.grid.height) - 4);
}

// A cell's centre is the exact double of its pixel's, in every build
// (through float and back it was not: docs/results.md, "Cheaper candidates").
TEST(Slices, ACellsCentreIsExactInDouble) {
  SliceGrid g;
  g.cell = 0.1, g.x_min = -4.0877, g.y_min = 10.3, g.width = 176, g.height = 174;
  for (const uint32_t index : {0u, 175u, 176u, 12345u, 176u * 174u - 1u}) {
    const int u = static_cast<int>(index % 176), v = static_cast<int>(index / 176);
    const Eigen::Vector2d c = g.cellCentre(index);
    EXPECT_EQ(c.x(), -4.0877 + (u + 0.5) * 0.1) << index;
    EXPECT_EQ(c.y(), 10.3 + (v + 0.5) * 0.1) << index;
    EXPECT_EQ(c, g.pixelCentre(u, v));
    EXPECT_NEAR(g.toPixel(c.x(), c.y()).x(), u, 1e-9);
  }
}
