// The fleet's map (core/fleet_map.hpp): maps placed and merged on one
// lattice, the floor found, the 2D grid of a height band.
#include <gtest/gtest.h>

#include <algorithm>

#include "core/fleet_map.hpp"

using namespace tomomap;

namespace {

constexpr double kGrid = 0.1;

/// A room 4 x 3 m seen by a robot: a floor at z = -1, walls to z = 1.5.
Points room() {
  Points p;
  for (double x = 0.05; x < 4; x += kGrid)
    for (double y = 0.05; y < 3; y += kGrid) p.emplace_back(x, y, -0.95);
  for (double z = -0.95; z < 1.5; z += kGrid) {
    for (double x = 0.05; x < 4; x += kGrid) p.emplace_back(x, 0.05, z);
    for (double y = 0.05; y < 3; y += kGrid) p.emplace_back(0.05, y, z);
  }
  return p;
}

}  // namespace

TEST(FleetMap, OverlappingMapsShareTheirCellsAndTheFirstKeepsThem) {
  const Points a = room();
  // Bravo mapped the same room from a frame 1 m along x and turned a quarter: placed back by its pose.
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T(0, 3) = 1.0;
  Points b;
  const Eigen::Matrix4d back = T.inverse();
  for (const auto& p : a)
    b.push_back((back.topLeftCorner<3, 3>() * p.cast<double>() + back.topRightCorner<3, 1>()).cast<float>());
  const FleetMap m = mergeMaps({{"alpha", a, Eigen::Matrix4d::Identity()}, {"bravo", b, T}}, kGrid);
  ASSERT_EQ(m.agents, (std::vector<std::string>{"alpha", "bravo"}));
  EXPECT_EQ(m.points.size(), m.cells_of[0]) << "bravo's cells are alpha's";
  EXPECT_EQ(m.cells_of[0], m.cells_of[1]);
  for (uint32_t r : m.robot) EXPECT_EQ(r, 0u);
  // Placed one cell off, they are two maps' cells.
  T(0, 3) += kGrid;
  const FleetMap off = mergeMaps({{"alpha", a, Eigen::Matrix4d::Identity()}, {"bravo", b, T}}, kGrid);
  EXPECT_GT(off.points.size(), m.points.size());
  EXPECT_THROW(mergeMaps({}, 0.0), InputError);
}

TEST(FleetMap, TheFloorIsTheFullestLowLayerAndTheGridHoldsTheBandsCells) {
  const FleetMap m = mergeMaps({{"alpha", room(), Eigen::Matrix4d::Identity()}}, kGrid);
  EXPECT_NEAR(floorHeight(m), -0.95, 1e-6);
  const OccupancyGrid2D g = occupancyGrid(m, -0.95 + 0.2, -0.95 + 1.5);
  EXPECT_DOUBLE_EQ(g.resolution, kGrid);
  EXPECT_NEAR(g.x_min, 0.0, 1e-9);
  EXPECT_NEAR(g.y_min, 0.0, 1e-9);
  EXPECT_EQ(g.width, 40);
  EXPECT_EQ(g.height, 30);
  EXPECT_EQ(g.at(0, 15), OccupancyGrid2D::kOccupied) << "the wall along y";
  EXPECT_EQ(g.at(20, 0), OccupancyGrid2D::kOccupied) << "the wall along x";
  EXPECT_EQ(g.at(20, 15), OccupancyGrid2D::kUnknown) << "the floor is no obstacle";
  EXPECT_TRUE(std::isnan(floorHeight(FleetMap{})));
  EXPECT_EQ(occupancyGrid(FleetMap{}, 0, 1).cells.size(), 0u);
}

TEST(FleetMap, ASliceStacksCellsLieWhereItsPointsAreAtTheirSlicesHeights) {
  // The room sliced as a daemon slices a map (off the lattice's edges by a
  // quarter cell): the cells it holds of it are where the room's points are.
  Points points = room();
  for (auto& p : points) p.head<2>().array() += 0.025f;
  const SliceStack stack = makeSlices(points, kGrid, 1);
  const Points cells = occupiedCells(stack);
  size_t held = 0;
  for (const auto& slice : stack.cells) held += slice.size();
  ASSERT_EQ(cells.size(), held);
  ASSERT_GT(held, 1000u);
  for (const auto& c : cells) {
    const bool near = std::any_of(points.begin(), points.end(), [&](const Eigen::Vector3f& p) {
      return (p - c).cwiseAbs().maxCoeff() <= 0.5f * static_cast<float>(kGrid) + 1e-4f;
    });
    ASSERT_TRUE(near) << c.transpose();
  }
  // Merged alone, it is the room: its floor where the room's is, the walls in the band.
  const FleetMap map = mergeMaps({{"alpha", cells, Eigen::Matrix4d::Identity()}}, kGrid);
  const FleetGrid grid = fleetGrid(map, HeightBand{});
  EXPECT_NEAR(grid.floor, -0.95, 0.5 * kGrid);
  EXPECT_NEAR(grid.z_high - grid.z_low, HeightBand{}.high - HeightBand{}.low, 1e-9);
  size_t occupied = 0;
  for (const int8_t v : grid.grid.cells) occupied += v == OccupancyGrid2D::kOccupied;
  // The two walls seen from above (69 columns, less the ends slicing left out as
  // stray returns), and nothing of the floor's 1,200.
  EXPECT_LE(occupied, 40u + 30u - 1u);
  EXPECT_GE(occupied, 55u);
}
