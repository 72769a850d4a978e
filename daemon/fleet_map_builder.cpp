#include "fleet_map_builder.hpp"


#include "clock.hpp"
#include "viz/fleet_map_files.hpp"

namespace tomomap::daemon {
namespace {

/// A map's slices as the fleet's map sees them: those whose cells are held
/// here, and those that crossed the link as features alone (no cells).
nlohmann::json coverage(const MapFeatures& m) {
  int as_features = 0;
  for (const auto& s : m.slices) {
    const auto k = static_cast<size_t>(s.index);
    as_features += k >= m.occupancy.cells.size() || m.occupancy.cells[k].empty();
  }
  return {{"slices_with_cells", m.occupancy.occupiedSlices()}, {"slices_as_features", as_features}};
}

FleetMapBuilt build(const FleetMapJob& job) {
  std::vector<PlacedMap> placed;
  nlohmann::json robots = nlohmann::json::array();
  for (const auto& part : job.parts) {
    placed.push_back({part.agent, occupiedCells(part.map->occupancy), part.T_root_map.matrix()});
    nlohmann::json robot = coverage(*part.map);
    robot["agent"] = part.agent;
    robots.push_back(std::move(robot));
  }
  auto map = std::make_shared<const FleetMap>(mergeMaps(placed, job.grid));
  auto grid = std::make_shared<const FleetGrid>(fleetGrid(*map, job.band));
  for (size_t r = 0; r < robots.size(); ++r) robots[r]["cells"] = map->cells_of[r];
  const std::string stem =
      viz::writeFleetMapFiles(job.dir, *map, *grid, viz::fleetMapCaption(*map, *grid, job.band, job.where));
  const OccupancyGrid2D& g = grid->grid;
  nlohmann::json status{{"cells", map->points.size()},
                        {"robots", robots},
                        {"frame", job.where},
                        {"floor_z", grid->floor},
                        {"grid", {{"width", g.width}, {"height", g.height}, {"resolution", g.resolution}}},
                        {"files", stem + ".{pcd,pgm,yaml,png}"}};
  return {std::move(status), std::move(map), std::move(grid)};
}

}  // namespace

FleetMapBuilder::~FleetMapBuilder() {
  if (thread_.joinable()) thread_.join();
}

void FleetMapBuilder::start(FleetMapJob job) {
  done_ = false;
  thread_ = std::thread([this, job = std::move(job)] {
    const auto t0 = Clock::now();
    FleetMapBuilt r;
    try {
      r = build(job);
    } catch (const std::exception& e) {
      // A map too large for a grid, a full disk: said in status.json and the
      // log; tried again after `interval_s`.
      r.status = {{"error", e.what()}};
    }
    r.status["built_at_ms"] = wallMs();
    r.status["seconds"] = seconds(Clock::now() - t0);
    result_ = std::move(r);
    done_ = true;
    wake_();
  });
}

FleetMapBuilt FleetMapBuilder::take() {
  thread_.join();
  done_ = false;
  return std::move(result_);
}

}  // namespace tomomap::daemon
