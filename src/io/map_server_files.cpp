#include "map_server_files.hpp"

#include <filesystem>
#include <fstream>
#include <iomanip>

namespace tomomap {

void saveMapServerMap(const std::string& stem, const OccupancyGrid2D& grid) {
  if (grid.width <= 0 || grid.height <= 0) throw InputError(stem + ".pgm: an empty grid has no map");
  // map_saver's trinary values; map_server reads them back with the thresholds below.
  constexpr uint8_t kOccupied = 0, kFree = 254, kUnknown = 205;
  // Binary PGM (P5) is a one-line header and the bytes, written here: OpenCV's
  // imgcodecs would map GDAL and a dozen image libraries into the daemon.
  std::string image(static_cast<size_t>(grid.width) * static_cast<size_t>(grid.height), '\0');
  for (int row = 0; row < grid.height; ++row)
    for (int column = 0; column < grid.width; ++column) {
      const int8_t v = grid.at(column, row);
      image[static_cast<size_t>(grid.height - 1 - row) * static_cast<size_t>(grid.width) +
            static_cast<size_t>(column)] = static_cast<char>(v == OccupancyGrid2D::kOccupied ? kOccupied
                                                             : v == 0                        ? kFree
                                                                                             : kUnknown);
    }
  const std::string pgm = stem + ".pgm";
  std::ofstream out(pgm, std::ios::binary);
  out << "P5\n" << grid.width << " " << grid.height << "\n255\n" << image;
  if (!out.flush()) throw InputError(pgm + ": cannot write the map image");

  std::ofstream yaml(stem + ".yaml");
  yaml << std::setprecision(9) << "image: " << std::filesystem::path(pgm).filename().string() << "\n"
       << "mode: trinary\n"
       << "resolution: " << grid.resolution << "\n"
       << "origin: [" << grid.x_min << ", " << grid.y_min << ", 0]\n"
       << "negate: 0\n"
       << "occupied_thresh: 0.65\n"
       << "free_thresh: 0.25\n";
  if (!yaml.flush()) throw InputError(stem + ".yaml: cannot write the map's description");
}

}  // namespace tomomap
