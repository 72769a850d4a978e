// The fleet's map (core/fleet_map.hpp): maps placed and merged on one
// lattice, the floor found, the 2D grid of a height band.
#include <gtest/gtest.h>

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
