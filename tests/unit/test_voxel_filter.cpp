#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <tuple>

#include "core/voxel_filter.hpp"

using namespace tomomap;

TEST(VoxelFilter, EmptyInputGivesEmptyOutput) { EXPECT_TRUE(voxelFilter({}, 0.1).empty()); }

TEST(VoxelFilter, ReplacesEachCellByItsCentroid) {
  // Two points share the first 1 m cell, one sits alone in another.
  const Points in{{0.1f, 0.1f, 0.1f}, {0.3f, 0.5f, 0.1f}, {2.5f, 0.2f, 0.2f}};
  const Points out = voxelFilter(in, 1.0);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_NEAR(out[0].x(), 0.2f, 1e-6);
  EXPECT_NEAR(out[0].y(), 0.3f, 1e-6);
  EXPECT_NEAR(out[1].x(), 2.5f, 1e-6);
}

TEST(VoxelFilter, HandlesExtentsThatOverflow32BitCellCounts) {
  // 2 km x 2 km x 100 m at 0.05 m is 1.6e11 cells: PCL's VoxelGrid gives up here.
  const Points in{{0, 0, 0}, {2000, 2000, 100}, {2000.01f, 2000.01f, 100.01f}};
  EXPECT_EQ(voxelFilter(in, 0.05).size(), 2u);
}

TEST(VoxelFilter, RejectsNonPositiveLeaf) { EXPECT_THROW(voxelFilter({{0, 0, 0}}, 0.0), InputError); }

// The centroids, in cell order (z, then y, then x) and summed in point order,
// as a plain map of cells computes them: the filter bins a layer in place, or
// sorts it where the layer has more cells than the map has points, which must
// not change a bit.
class VoxelFilterPaths : public ::testing::TestWithParam<float> {};

TEST_P(VoxelFilterPaths, GiveWhatAPlainMapOfCellsGivesBitForBit) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> x(-3.f, 5.f), z(-0.4f, 2.6f);
  Points in(200000);
  for (auto& p : in) p = {x(rng), x(rng), z(rng)};
  // A far point: many empty layers and columns. At 15 m, 130 k cells a layer
  // (binned in place: under the 200 k points); at 400 m, 64 M (sorted).
  in.push_back({GetParam(), GetParam(), 0.f});
  const float leaf = 0.05f;
  Eigen::Vector3f lo = in.front();
  for (const auto& p : in) lo = lo.cwiseMin(p);
  std::map<std::tuple<long, long, long>, std::pair<Eigen::Vector3d, int>> cells;
  for (const auto& p : in) {
    const Eigen::Vector3f d = p - lo;
    auto& [sum, n] =
        cells[{static_cast<long>(d.z() / leaf), static_cast<long>(d.y() / leaf), static_cast<long>(d.x() / leaf)}];
    if (n++ == 0) sum.setZero();
    sum += p.cast<double>();
  }
  const Points out = voxelFilter(in, leaf);
  ASSERT_EQ(out.size(), cells.size());
  size_t k = 0;
  for (const auto& [cell, acc] : cells) {
    const Eigen::Vector3f expected = (acc.first / static_cast<double>(acc.second)).cast<float>();
    ASSERT_EQ(out[k], expected) << "cell " << k;
    ++k;
  }
}

INSTANTIATE_TEST_SUITE_P(VoxelFilter, VoxelFilterPaths, ::testing::Values(15.f, 400.f));

TEST(VoxelFilter, HandlesLayersOfMoreThan32BitCells) {
  // 300 km x 300 km at 0.05 m: more than 2^32 cells in one layer, sorted whole.
  const Points in{{0, 0, 0}, {300000, 300000, 0}, {300000.01f, 300000.01f, 0.01f}, {0.01f, 0.01f, 0.01f}};
  const Points out = voxelFilter(in, 0.05);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_NEAR(out[0].x(), 0.005f, 1e-6);
}
