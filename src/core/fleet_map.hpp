#pragma once
// The fleet's map: every robot's occupied cells placed in one frame and
// merged at the grid, and its 2D occupancy grid for a height band. Built from
// cells (voxel centres), which is what a daemon holds of every peer's map
// (its slices), never from raw maps.
#include <cstdint>
#include <string>
#include <vector>

#include "slices.hpp"
#include "types.hpp"

namespace tomomap {

/// One robot's map as the fleet places it.
struct PlacedMap {
  std::string agent;
  Points cells;                                              // occupied cells' centres in the map's own frame [m]
  Eigen::Matrix4d T_root_map = Eigen::Matrix4d::Identity();  ///< p_root = T_root_map * p_map (rigid)
};

struct FleetMap {
  double grid = 0;                  ///< cell size [m]
  std::vector<std::string> agents;  ///< the robots, in the order they were given
  Points points;                    ///< occupied cells' centres in the root frame, one a cell [m]
  /// Per point: the index in `agents` of the first robot whose map occupies
  /// the cell (where maps overlap, the earlier one's).
  std::vector<uint32_t> robot;
  std::vector<size_t> cells_of;  ///< per robot: the cells its map occupies in the root frame (shared ones included)
};

/// The occupied cells of a stack of slices: each cell's centre in the frame
/// the map was sliced in (levelled where it was), at its slice's height.
/// Slices without cells (too sparse to describe, or received as features) add none.
Points occupiedCells(const SliceStack& stack);

/// Places every map by its transform and merges them on the root frame's
/// lattice of `grid` (cells with a corner at the origin): each occupied cell
/// once. Throws InputError where they span more than 2^20 cells along an axis.
FleetMap mergeMaps(const std::vector<PlacedMap>& maps, double grid);

/// The height of the fleet map's floor (or ground) [m]: the centre of the
/// lowest lattice layer holding at least half as many cells as the fullest
/// one. Floors and ceilings are a map's largest horizontal surfaces; the
/// lowest of them is the ground floor (a few returns below it, a cell layer
/// of a staircase, do not count). NaN for an empty map.
double floorHeight(const FleetMap& map);

/// The heights a 2D grid sees, above the floor [m]: what a ground robot's
/// body meets. The default clears the floor's own cells and a low kerb and
/// reaches a person's shoulder: a wheeled robot's sensors and arm.
struct HeightBand {
  double low = 0.2, high = 1.5;
  bool valid() const { return low < high; }
};

/// A 2D occupancy grid in ROS's nav_msgs/OccupancyGrid convention: row 0 at
/// `y_min`, column 0 at `x_min`, values 100 occupied, 0 free, -1 unknown.
struct OccupancyGrid2D {
  double resolution = 0;        ///< [m]
  double x_min = 0, y_min = 0;  ///< the corner of cell (0, 0) in the root frame [m]
  int width = 0, height = 0;
  std::vector<int8_t> cells;  ///< row-major, width x height
  static constexpr int8_t kOccupied = 100, kUnknown = -1;
  int8_t at(int column, int row) const { return cells[static_cast<size_t>(row) * width + column]; }
};

/// The largest 2D grid occupancyGrid makes (100 M cells, 100 MB).
constexpr double kMaxGridCells = 1e8;

/// The cells of the fleet map whose height lies in [z_low, z_high] seen from
/// above: occupied where one is, unknown elsewhere (the slices carry where a
/// map is occupied, not where a robot saw free space). Covers every cell of the map.
OccupancyGrid2D occupancyGrid(const FleetMap& map, double z_low, double z_high);

/// The fleet map's 2D view: its floor, the band's heights above it, and the grid of them.
struct FleetGrid {
  double floor = 0;                 ///< floorHeight [m]
  double z_low = 0, z_high = 0;     ///< the band above the floor [m]
  OccupancyGrid2D grid;
};
/// The same for `band`; throws InputError like occupancyGrid.
FleetGrid fleetGrid(const FleetMap& map, const HeightBand& band);

}  // namespace tomomap
