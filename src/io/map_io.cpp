#include "map_io.hpp"

#include <pcl/common/io.h>
#include <pcl/console/print.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "core/map_check.hpp"
#include "pcd_check.hpp"

namespace tomomap {
namespace {

std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// PCL reports parse problems on stderr; we report them ourselves, once.
void silencePcl() { pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS); }

/// Reads x, y, z straight out of PCL's blob: no intermediate PointCloud, which
/// for a map of millions of points would hold a third copy in memory.
Points fromBlob(const pcl::PCLPointCloud2& blob, const std::string& path) {
  int offset[3];
  uint8_t type[3];
  const char* axes[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    const int f = pcl::getFieldIndex(blob, axes[a]);
    if (f < 0) throw InputError(path + ": has no '" + axes[a] + "' field");
    offset[a] = static_cast<int>(blob.fields[static_cast<size_t>(f)].offset);
    type[a] = blob.fields[static_cast<size_t>(f)].datatype;
    if (type[a] != pcl::PCLPointField::FLOAT32 && type[a] != pcl::PCLPointField::FLOAT64)
      throw InputError(path + ": field '" + axes[a] + "' is not a float");
  }
  const size_t n = static_cast<size_t>(blob.width) * blob.height;
  if (blob.point_step == 0 || blob.data.size() < n * blob.point_step)
    throw InputError(path + ": truncated (header declares " + std::to_string(n) + " points)");
  Points out(n);
  for (size_t i = 0; i < n; ++i) {
    const uint8_t* p = blob.data.data() + i * blob.point_step;
    for (int a = 0; a < 3; ++a) {
      if (type[a] == pcl::PCLPointField::FLOAT32) {
        float v;
        std::memcpy(&v, p + offset[a], sizeof v);
        out[i][a] = v;
      } else {
        double v;
        std::memcpy(&v, p + offset[a], sizeof v);
        out[i][a] = static_cast<float>(v);
      }
    }
  }
  return out;
}

Points loadPcl(const std::string& path, bool ply) {
  silencePcl();
  if (!ply) checkPcdIntegrity(path);
  pcl::PCLPointCloud2 blob;
  const int rc = ply ? pcl::io::loadPLYFile(path, blob) : pcl::io::loadPCDFile(path, blob);
  if (rc < 0) throw InputError(path + ": not a readable " + (ply ? "PLY" : "PCD") + " file (corrupt or truncated)");
  return fromBlob(blob, path);
}

Points loadXyz(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open");
  Points out;
  std::string line;
  for (size_t number = 1; std::getline(in, line); ++number) {
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.erase(hash);
    if (line.find_first_not_of(" \t\r,") == std::string::npos) continue;
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream fields(line);
    double x, y, z;
    // Reading via strings lets "nan"/"inf" through to the finiteness check below.
    std::string sx, sy, sz;
    if (!(fields >> sx >> sy >> sz)) throw InputError(path + ":" + std::to_string(number) + ": expected 'x y z'");
    try {
      size_t px, py, pz;
      x = std::stod(sx, &px);
      y = std::stod(sy, &py);
      z = std::stod(sz, &pz);
      if (px != sx.size() || py != sy.size() || pz != sz.size()) throw std::invalid_argument("");
    } catch (const std::exception&) {
      throw InputError(path + ":" + std::to_string(number) + ": not a number in '" + line + "'");
    }
    out.emplace_back(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
  }
  return out;
}

}  // namespace

Points loadMap(const std::string& path, size_t* nonfinite) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError(path + ": no such file");
  if (std::filesystem::is_directory(path, ec)) throw InputError(path + ": is a directory, not a map file");
  if (std::filesystem::file_size(path, ec) == 0) throw InputError(path + ": file is empty");

  const std::string ext = lowerExtension(path);
  Points points;
  if (ext == ".pcd")
    points = loadPcl(path, false);
  else if (ext == ".ply")
    points = loadPcl(path, true);
  else if (ext == ".xyz" || ext == ".txt")
    points = loadXyz(path);
  else
    throw InputError(path + ": unknown map format '" + ext + "' (use .pcd, .ply, .xyz or .txt)");
  const size_t read = points.size(), dropped = dropNonFinite(points);
  if (nonfinite) *nonfinite = dropped;
  if (dropped > 0 && points.size() < kMinMapPoints)
    throw InputError(path + ": only " + std::to_string(points.size()) + " of " + std::to_string(read) +
                     " points are finite (the rest NaN or infinite); at least " + std::to_string(kMinMapPoints) +
                     " are needed");
  validateMap(points, path);
  return points;
}

void savePcd(const std::string& path, const Points& points) {
  silencePcl();
  pcl::PointCloud<pcl::PointXYZ> cloud;
  cloud.reserve(points.size());
  for (const auto& p : points) cloud.push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  if (cloud.empty() || pcl::io::savePCDFileBinaryCompressed(path, cloud) < 0)
    throw InputError(path + ": cannot write map");
}

Eigen::Matrix4d loadPoseFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open pose file");
  std::vector<double> v;
  std::string token;
  while (in >> token) {
    try {
      size_t used;
      v.push_back(std::stod(token, &used));
      if (used != token.size()) throw std::invalid_argument("");
    } catch (const std::exception&) {
      throw InputError(path + ": pose file has a non-number '" + token + "'");
    }
    if (!std::isfinite(v.back())) throw InputError(path + ": pose file has a non-finite number");
  }
  if (v.size() != 12)
    throw InputError(path + ": pose file must hold 12 numbers (3x4 row-major), found " + std::to_string(v.size()));
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = v[static_cast<size_t>(r * 4 + c)];
  const Eigen::Matrix3d R = m.topLeftCorner<3, 3>();
  if (!(R.transpose() * R).isIdentity(1e-3)) throw InputError(path + ": pose rotation is not orthonormal");
  return m;
}

void savePoseFile(const std::string& path, const Eigen::Matrix4d& pose) {
  std::ofstream out(path);
  out << std::setprecision(17);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) out << pose(r, c) << (r == 2 && c == 3 ? "\n" : " ");
  if (!out) throw InputError(path + ": cannot write pose file");
}

}  // namespace tomomap
