#include "fleet_map.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "lattice.hpp"

namespace tomomap {

Points occupiedCells(const SliceStack& stack) {
  Points out;
  size_t total = 0;
  for (const auto& slice : stack.cells) total += slice.size();
  out.reserve(total);
  for (int k = 0; k < stack.size(); ++k) {
    const auto z = static_cast<float>(stack.grid.sliceHeight(k));
    for (const uint32_t cell : stack.cells[static_cast<size_t>(k)]) {
      const Eigen::Vector2d xy = stack.grid.cellCentre(cell);
      out.emplace_back(static_cast<float>(xy.x()), static_cast<float>(xy.y()), z);
    }
  }
  return out;
}

FleetMap mergeMaps(const std::vector<PlacedMap>& maps, double grid) {
  if (!(grid > 0)) throw InputError("the fleet map's grid must be positive");
  FleetMap out;
  out.grid = grid;
  // Every placed cell with its lattice key and map, sorted by key (then map):
  // a sort, not a hash set of millions of nodes, which took 4 of the 6 s of
  // merging three 0.8 M-cell maps.
  struct Placed {
    uint64_t key;
    uint32_t map;
    Eigen::Vector3f centre;
  };
  std::vector<Placed> all;
  size_t total = 0;
  for (const auto& m : maps) total += m.cells.size();
  all.reserve(total);
  for (uint32_t m = 0; m < maps.size(); ++m) {
    out.agents.push_back(maps[m].agent);
    const Eigen::Matrix4d& T = maps[m].T_root_map;
    for (const Eigen::Vector3f& c : maps[m].cells) {
      const Eigen::Vector3f p = (T.topLeftCorner<3, 3>() * c.cast<double>() + T.topRightCorner<3, 1>()).cast<float>();
      all.push_back({latticeKey(p, grid), m, latticeCentre(p, grid)});
    }
  }
  std::sort(all.begin(), all.end(),
            [](const Placed& a, const Placed& b) { return a.key != b.key ? a.key < b.key : a.map < b.map; });
  out.cells_of.assign(maps.size(), 0);
  for (size_t i = 0; i < all.size(); ++i) {
    const bool new_cell = i == 0 || all[i].key != all[i - 1].key;
    // Each map's cells once (a map may hold two points in one root cell).
    if (new_cell || all[i].map != all[i - 1].map) ++out.cells_of[all[i].map];
    if (!new_cell) continue;  // where maps overlap, the earlier map's
    out.points.push_back(all[i].centre);
    out.robot.push_back(all[i].map);
  }
  // Cells 2^21 apart share a lattice key: a map that spans that many is no fleet's map.
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(INFINITY), hi = -lo;
  for (const auto& p : out.points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  if (!out.points.empty() && ((hi - lo).array() / static_cast<float>(grid) >= float(1 << 20)).any())
    throw InputError("the fleet map spans more than 2^20 cells along an axis at " + std::to_string(grid) +
                     " m: maps placed this far apart are not one place");
  return out;
}

double floorHeight(const FleetMap& map) {
  if (map.points.empty()) return NAN;
  std::map<int64_t, size_t> layers;  // by height
  for (const auto& p : map.points) ++layers[static_cast<int64_t>(std::floor(p.z() / map.grid))];
  size_t fullest = 0;
  for (const auto& [layer, cells] : layers) fullest = std::max(fullest, cells);
  for (const auto& [layer, cells] : layers)
    if (2 * cells >= fullest) return (static_cast<double>(layer) + 0.5) * map.grid;
  return NAN;  // not reached: the fullest layer qualifies
}

OccupancyGrid2D occupancyGrid(const FleetMap& map, double z_low, double z_high) {
  OccupancyGrid2D g;
  g.resolution = map.grid;
  if (map.points.empty()) return g;
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(INFINITY), hi = -lo;
  for (const auto& p : map.points) {
    lo = lo.cwiseMin(p.head<2>().cast<double>());
    hi = hi.cwiseMax(p.head<2>().cast<double>());
  }
  // The points are cell centres: the grid's cells are the lattice's.
  g.x_min = std::floor(lo.x() / map.grid) * map.grid;
  g.y_min = std::floor(lo.y() / map.grid) * map.grid;
  const Eigen::Vector2d cells = (hi - Eigen::Vector2d(g.x_min, g.y_min)) / map.grid;
  if (cells.x() * cells.y() > kMaxGridCells)
    throw InputError("the fleet map spans " + std::to_string(std::lround(hi.x() - lo.x())) + " x " +
                     std::to_string(std::lround(hi.y() - lo.y())) + " m: too large a 2D grid at " +
                     std::to_string(map.grid) + " m (maps placed this far apart are not one place)");
  g.width = static_cast<int>(std::lround((hi.x() - g.x_min) / map.grid + 0.5));
  g.height = static_cast<int>(std::lround((hi.y() - g.y_min) / map.grid + 0.5));
  g.cells.assign(static_cast<size_t>(g.width) * static_cast<size_t>(g.height), OccupancyGrid2D::kUnknown);
  for (const auto& p : map.points) {
    if (p.z() < z_low || p.z() > z_high) continue;
    const int column = std::clamp(static_cast<int>((p.x() - g.x_min) / map.grid), 0, g.width - 1);
    const int row = std::clamp(static_cast<int>((p.y() - g.y_min) / map.grid), 0, g.height - 1);
    g.cells[static_cast<size_t>(row) * static_cast<size_t>(g.width) + static_cast<size_t>(column)] =
        OccupancyGrid2D::kOccupied;
  }
  return g;
}

FleetGrid fleetGrid(const FleetMap& map, const HeightBand& band) {
  FleetGrid g;
  g.floor = floorHeight(map);
  g.z_low = g.floor + band.low;
  g.z_high = g.floor + band.high;
  g.grid = occupancyGrid(map, g.z_low, g.z_high);
  return g;
}

}  // namespace tomomap
