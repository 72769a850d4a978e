#pragma once
// Reading and writing map files: the only file I/O the core does.
#include <string>

#include "types.hpp"

namespace tomomap {

/// Smallest map the matcher accepts: below this there is nothing to slice.
constexpr size_t kMinMapPoints = 100;

/// Loads a map: .pcd (ascii, binary, binary_compressed), .ply, or .xyz/.txt
/// (one "x y z" per line, '#' comments). Throws InputError naming the file and
/// the problem for a missing, unreadable, corrupt, empty or non-finite map.
Points loadMap(const std::string& path);

/// Checks points the way loadMap does; `what` names the source in messages.
void validateMap(const Points& points, const std::string& what);

/// Writes a binary_compressed PCD (x y z float). Throws InputError on failure.
void savePcd(const std::string& path, const Points& points);

/// Reads a pose file: 12 numbers, the top 3x4 of a 4x4 map-to-world matrix,
/// row-major. Throws InputError naming the file and the problem.
Eigen::Matrix4d loadPoseFile(const std::string& path);

/// Writes a pose file in the same format.
void savePoseFile(const std::string& path, const Eigen::Matrix4d& pose);

}  // namespace tomomap
