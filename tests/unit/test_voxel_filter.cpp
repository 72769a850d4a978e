#include <gtest/gtest.h>

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
