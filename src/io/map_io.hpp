#pragma once
// Reading and writing map and pose files (PCL's io only through pcl_module.hpp).
#include <string>

#include "core/map_check.hpp"
#include "core/types.hpp"

namespace tomomap {

/// Bytes of a binary PCD of `points` x y z floats (header included): what
/// shipping the raw map would cost, the yardstick for every payload figure.
constexpr size_t kPcdBytesPerPoint = 3 * sizeof(float);
constexpr size_t kPcdHeaderBytes = 190;
constexpr uint64_t binaryPcdBytes(size_t points) { return kPcdBytesPerPoint * points + kPcdHeaderBytes; }

/// Loads a map: .pcd (ascii, binary, binary_compressed), .ply (a mesh's
/// vertices), .xyz/.txt/.csv (one "x y z" per line, commas or spaces, '#'
/// comments, an optional first line naming the columns), or OctoMap .bt/.ot
/// (occupied voxel centres). Points with a NaN or infinite coordinate are
/// dropped and counted in `*nonfinite`; `*note` gets what a user should know
/// about how the file was read (a mesh's faces unused), if anything. Throws
/// InputError naming the file and the problem for a missing, unreadable,
/// corrupt or empty map, or one with fewer than kMinMapPoints finite points.
Points loadMap(const std::string& path, size_t* nonfinite = nullptr, std::string* note = nullptr);

/// How savePcd stores the points. Plain binary by default: x, y, z floats do
/// not compress (the building's map: 22.24 MB plain, 22.42 MB through LZF) and
/// decompressing costs time on every load (0.016 s of its 0.027).
enum class PcdData { binary, binary_compressed };

/// Writes a PCD (x y z float). Throws InputError on failure.
void savePcd(const std::string& path, const Points& points, PcdData data = PcdData::binary);

/// Writes a binary PCD of x y z rgb label (PCL's PointXYZRGBL, what RViz
/// colours by): each point's label and its label's colour (`colours[label]`,
/// 0xRRGGBB). Throws InputError if it cannot be written.
void saveLabelledPcd(const std::string& path, const Points& points, const std::vector<uint32_t>& labels,
                     const std::vector<uint32_t>& colours);

/// Reads a pose file: 12 numbers, the top 3x4 of a 4x4 map-to-world matrix,
/// row-major. Throws InputError naming the file and the problem.
Eigen::Matrix4d loadPoseFile(const std::string& path);

/// Writes a pose file in the same format.
void savePoseFile(const std::string& path, const Eigen::Matrix4d& pose);

}  // namespace tomomap
