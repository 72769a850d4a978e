// What bounds reading and voxel-filtering a map: for a binary_compressed PCD,
// its LZF decompression beside a plain copy of the same bytes; then loadMap
// whole, the voxel filter, and one pass that only sums the points. Medians.
// Usage: bench_load MAP.pcd GRID [RUNS]
#include <lzf.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "core/stats.hpp"
#include "core/voxel_filter.hpp"
#include "io/map_io.hpp"
#include "support.hpp"

using namespace tomomap;
using test::secondsOf;

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: bench_load MAP.pcd GRID [RUNS]\n");
    return 2;
  }
  const std::string path = argv[1];
  const double grid = std::stod(argv[2]);
  const int runs = argc > 3 ? std::stoi(argv[3]) : 7;
  std::ifstream in(path, std::ios::binary);
  const std::string file((std::istreambuf_iterator<char>(in)), {});
  const std::string marker = "DATA binary_compressed\n";
  const size_t data = file.find(marker);
  uint32_t packed = 0, unpacked = 0;
  if (data != std::string::npos && data + marker.size() + 8 <= file.size()) {
    std::memcpy(&packed, file.data() + data + marker.size(), 4);
    std::memcpy(&unpacked, file.data() + data + marker.size() + 4, 4);
  }
  std::vector<char> raw(unpacked), copy(unpacked);
  std::vector<double> decompress, memcopy, load, voxel, pass;
  size_t points = 0, voxels = 0;
  for (int r = 0; r < runs; ++r) {
    if (unpacked > 0) {
      decompress.push_back(secondsOf([&] {
        lzf_decompress(file.data() + data + marker.size() + 8, packed, raw.data(), unpacked);
      }));
      memcopy.push_back(secondsOf([&] { std::memcpy(copy.data(), raw.data(), unpacked); }));
    }
    Points map;
    load.push_back(secondsOf([&] { map = loadMap(path); }));
    voxel.push_back(secondsOf([&] { voxels = voxelFilter(map, grid).size(); }));
    volatile double sum = 0;
    pass.push_back(secondsOf([&] {
      double s = 0;
      for (const auto& p : map) s += p.x() + p.y() + p.z();
      sum = s;
    }));
    points = map.size();
  }
  std::printf("%s: %zu points, %zu voxels at g %g; medians of %d runs\n", path.c_str(), points, voxels, grid, runs);
  if (unpacked > 0)
    std::printf("  binary_compressed: %u B packed, %u B unpacked; LZF decompression %.4f s, a copy of its bytes %.4f s\n",
                packed, unpacked, quantile(decompress, 0.5), quantile(memcopy, 0.5));
  std::printf("  loadMap %.4f s, voxel filter %.4f s, one pass summing the points %.4f s\n", quantile(load, 0.5),
              quantile(voxel, 0.5), quantile(pass, 0.5));
  return 0;
}
