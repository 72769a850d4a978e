#pragma once
// The map I/O that needs PCL's io library (PLY files, ascii PCD, writing PCD),
// built as a module that is loaded the first time a file needs it. Linking
// PCL's io into the binaries maps VTK, OpenNI, X11 and some 60 more libraries
// into every process: about 21 MB of a 36 MB `tomomap --version`
// (docs/results.md, "Memory"). Binary PCD files, what SLAM tools write and
// what the daemon loads, are read without it (pcd_check.hpp).
#include <cstdint>
#include <string>
#include <vector>

#include "core/types.hpp"

namespace tomomap {

/// The module's functions. Errors come back as text, never as exceptions: the
/// module has its own copy of tomomap's classes.
struct PclIo {
  /// Reads x, y, z of a PCD (`ply` false) or PLY file into *out.
  bool (*load)(const std::string& path, bool ply, Points* out, std::string* error);
  /// Writes a binary PCD (x y z float), LZF-compressed (binary_compressed) if `compressed`.
  bool (*savePcd)(const std::string& path, const Points& points, bool compressed, std::string* error);
  /// Writes a binary PCD of x y z rgb label (PCL's PointXYZRGBL): per point
  /// its label and that label's colour (`colours[label]`, 0xRRGGBB).
  bool (*saveLabelledPcd)(const std::string& path, const Points& points, const std::vector<uint32_t>& labels,
                          const std::vector<uint32_t>& colours, std::string* error);
};

/// Bumped whenever PclIo changes, so that a binary never calls a stale module.
constexpr unsigned kPclIoVersion = 3;
/// The module's file, looked up in the folders the program's RUNPATH names (CMakeLists.txt).
constexpr const char* kPclIoModule = "tomomap_pcl_io.so";
/// Its entry point: the functions, or nullptr if `version` is not its own.
constexpr const char* kPclIoEntry = "tomomap_pcl_io";
using PclIoEntry = const PclIo* (*)(unsigned version);

/// The loaded module's functions. Throws InputError saying what is missing if
/// the module cannot be loaded.
const PclIo& pclIo();

}  // namespace tomomap
