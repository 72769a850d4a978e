#include "fleet_map_files.hpp"

#include <filesystem>

#include "canvas.hpp"
#include "core/text.hpp"
#include "fleet_map_picture.hpp"
#include "io/map_io.hpp"
#include "io/map_server_files.hpp"

namespace tomomap::viz {

namespace fs = std::filesystem;

std::vector<std::string> fleetMapCaption(const FleetMap& map, const FleetGrid& grid, const HeightBand& band,
                                         const std::string& where) {
  return {"The fleet's map in " + where + ": " + std::to_string(map.agents.size()) + " robots, " +
              std::to_string(map.points.size()) + " cells at g " + fixed(map.grid, 2) + " m",
          "in colour: what each robot's map holds " + fixed(band.low, 2) + "-" + fixed(band.high, 2) +
              " m above the floor (z " + fixed(grid.floor, 2) + " m); grey: the rest"};
}

std::string writeFleetMapFiles(const std::string& dir, const FleetMap& map, const FleetGrid& grid,
                               const std::vector<std::string>& caption) {
  // One name: what a write that was killed left (the process's exit does not
  // wait for a build) goes with the next write.
  const fs::path staging = fs::path(dir) / ".fleet_map.staging";
  std::error_code ec;
  fs::remove_all(staging, ec);
  if (!fs::create_directories(staging, ec))
    throw InputError(staging.string() + ": cannot create a folder to write the fleet map in: " + ec.message());
  const auto cleanUp = [&] { fs::remove_all(staging, ec); };
  try {
    const std::string stem = (staging / "fleet_map").string();
    saveLabelledPcd(stem + ".pcd", map.points, map.robot, robotRgbs(map.agents.size()));
    saveMapServerMap(stem, grid.grid);
    writePng(stem + ".png", drawFleetMap(map, grid.z_low, grid.z_high, caption));
    for (const char* ext : {".pgm", ".yaml", ".pcd", ".png"}) {
      const fs::path to = fs::path(dir) / (std::string("fleet_map") + ext);
      fs::rename(stem + ext, to, ec);
      if (ec) throw InputError(to.string() + ": cannot write: " + ec.message());
    }
  } catch (...) {
    cleanUp();
    throw;
  }
  cleanUp();
  return (fs::path(dir) / "fleet_map").string();
}

}  // namespace tomomap::viz
