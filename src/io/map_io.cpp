#include "map_io.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <optional>
#include <sstream>

#include "core/map_check.hpp"
#include "octomap_io.hpp"
#include "pcd_check.hpp"
#include "pcl_module.hpp"

namespace tomomap {
namespace {

std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

Points loadPcdOrPly(const std::string& path, bool ply) {
  if (!ply)
    if (std::optional<Points> read = checkAndReadPcd(path)) return std::move(*read);
  Points points;
  std::string error;
  if (!pclIo().load(path, ply, &points, &error)) throw InputError(error);
  return points;
}

/// x, y, z from the first three whitespace-separated fields of `line`, if
/// they are numbers ("nan" and "inf" included: the finiteness check drops them).
std::optional<Eigen::Vector3d> threeNumbers(const std::string& line) {
  std::istringstream fields(line);
  std::string f[3];
  if (!(fields >> f[0] >> f[1] >> f[2])) return std::nullopt;
  Eigen::Vector3d v;
  for (int a = 0; a < 3; ++a) {
    size_t used = 0;
    try {
      v[a] = std::stod(f[a], &used);
    } catch (const std::exception&) {
      return std::nullopt;
    }
    if (used != f[a].size()) return std::nullopt;
  }
  return v;
}

/// How many faces a PLY file's header declares (a mesh: PCL reads its vertices only).
size_t plyFaces(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  size_t faces = 0;
  for (std::string line; std::getline(in, line) && line.rfind("end_header", 0) != 0;) {
    std::istringstream words(line);
    std::string element, name;
    if (words >> element >> name && element == "element" && name == "face") words >> faces;
  }
  return faces;
}

Points loadXyz(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open");
  Points out;
  std::string line;
  bool header_skipped = false;
  for (size_t number = 1; std::getline(in, line); ++number) {
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.erase(hash);
    if (line.find_first_not_of(" \t\r,") == std::string::npos) continue;
    std::replace(line.begin(), line.end(), ',', ' ');
    const auto p = threeNumbers(line);
    if (!p) {
      // Only the first line may name the columns (CloudCompare writes "//X,Y,Z").
      if (out.empty() && !header_skipped) {
        header_skipped = true;
        continue;
      }
      throw InputError(path + ":" + std::to_string(number) + ": expected 'x y z' numbers, got '" + line + "'");
    }
    out.push_back(p->cast<float>());
  }
  return out;
}

}  // namespace

Points loadMap(const std::string& path, size_t* nonfinite, std::string* note) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError(path + ": no such file");
  if (std::filesystem::is_directory(path, ec)) throw InputError(path + ": is a directory, not a map file");
  if (std::filesystem::file_size(path, ec) == 0) throw InputError(path + ": file is empty");

  const std::string ext = lowerExtension(path);
  Points points;
  if (ext == ".pcd")
    points = loadPcdOrPly(path, false);
  else if (ext == ".ply") {
    points = loadPcdOrPly(path, true);
    if (const size_t faces = plyFaces(path); faces > 0 && note)
      *note = path + ": a mesh: its " + std::to_string(points.size()) + " vertices are the map, its " +
              std::to_string(faces) + " faces are not used";
  } else if (ext == ".xyz" || ext == ".txt" || ext == ".csv")
    points = loadXyz(path);
  else if (ext == ".bt" || ext == ".ot")
    points = loadOctomap(path, ext == ".bt");
  else if (ext == ".las" || ext == ".laz")
    throw InputError(path + ": LAS/LAZ is not read; convert it first, e.g. pdal translate " + path + " map.pcd");
  else
    throw InputError(path + ": unknown map format '" + ext + "' (use .pcd, .ply, .xyz, .txt, .csv, .bt or .ot)");
  const size_t read = points.size(), dropped = dropNonFinite(points);
  if (nonfinite) *nonfinite = dropped;
  if (dropped > 0 && points.size() < kMinMapPoints)
    throw InputError(path + ": only " + std::to_string(points.size()) + " of " + std::to_string(read) +
                     " points are finite (the rest NaN or infinite); at least " + std::to_string(kMinMapPoints) +
                     " are needed");
  validateMap(points, path);
  return points;
}

void savePcd(const std::string& path, const Points& points, PcdData data) {
  std::string error;
  if (!pclIo().savePcd(path, points, data == PcdData::binary_compressed, &error)) throw InputError(error);
}

void saveLabelledPcd(const std::string& path, const Points& points, const std::vector<uint32_t>& labels,
                     const std::vector<uint32_t>& colours) {
  std::string error;
  if (!pclIo().saveLabelledPcd(path, points, labels, colours, &error)) throw InputError(error);
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
