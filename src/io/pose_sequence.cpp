#include "pose_sequence.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "map_io.hpp"

namespace tomomap {
namespace {

/// A quaternion as saved is unit to a few digits; farther off, it is not one.
constexpr double kQuaternionNormSlack = 1e-2;

/// A keyframe's pose from one line's numbers (KITTI 12, TUM 8, TUM without time 7).
Eigen::Matrix4d poseOf(const std::vector<double>& v) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  if (v.size() == 12) {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) T(r, c) = v[static_cast<size_t>(4 * r + c)];
    return T;
  }
  const size_t at = v.size() == 8 ? 1 : 0;  // TUM's first field is the time
  const Eigen::Quaterniond q(v[at + 6], v[at + 3], v[at + 4], v[at + 5]);
  if (std::abs(q.norm() - 1.0) > kQuaternionNormSlack) return Eigen::Matrix4d::Zero();  // no rotation: refused
  T.topLeftCorner<3, 3>() = q.normalized().toRotationMatrix();
  T.topRightCorner<3, 1>() = Eigen::Vector3d(v[at], v[at + 1], v[at + 2]);
  return T;
}

/// Scan files in keyframe order: names compared with their runs of digits as
/// numbers (FAST-LIO saves scans_1.pcd ... scans_10.pcd unpadded: 2 before 10).
bool namedBefore(const std::string& a, const std::string& b) {
  size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (std::isdigit(static_cast<unsigned char>(a[i])) && std::isdigit(static_cast<unsigned char>(b[j]))) {
      size_t ie = i, je = j;
      while (ie < a.size() && std::isdigit(static_cast<unsigned char>(a[ie]))) ++ie;
      while (je < b.size() && std::isdigit(static_cast<unsigned char>(b[je]))) ++je;
      const std::string x = a.substr(i, ie - i), y = b.substr(j, je - j);
      const size_t xz = x.find_first_not_of('0'), yz = y.find_first_not_of('0');
      const std::string xs = xz == std::string::npos ? "" : x.substr(xz),
                        ys = yz == std::string::npos ? "" : y.substr(yz);
      if (xs.size() != ys.size()) return xs.size() < ys.size();
      if (xs != ys) return xs < ys;
      i = ie;
      j = je;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i;
      ++j;
    }
  }
  return a.size() - i < b.size() - j;
}

}  // namespace

std::vector<Eigen::Matrix4d> loadPoseSequence(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open pose file");
  std::vector<Eigen::Matrix4d> poses;
  size_t line_no = 0, fields = 0;
  for (std::string line; std::getline(in, line);) {
    ++line_no;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    const std::string where = path + ":" + std::to_string(line_no) + ": ";
    std::vector<double> v;
    std::istringstream words(line);
    for (std::string token; words >> token;) {
      size_t used = 0;
      try {
        v.push_back(std::stod(token, &used));
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != token.size() || !std::isfinite(v.back()))
        throw InputError(where + "'" + token + "' is not a finite number");
    }
    if (v.size() != 12 && v.size() != 8 && v.size() != 7)
      throw InputError(where + std::to_string(v.size()) +
                       " numbers; a pose line holds 12 (KITTI: 3x4 row-major), 8 (TUM: time x y z qx qy qz qw) or 7 "
                       "(x y z qx qy qz qw)");
    if (fields != 0 && v.size() != fields)
      throw InputError(where + std::to_string(v.size()) + " numbers where the lines above hold " +
                       std::to_string(fields));
    fields = v.size();
    const Eigen::Matrix4d T = poseOf(v);
    const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
    if (!(R.transpose() * R).isIdentity(1e-3) || R.determinant() < 0)
      throw InputError(where + "the rotation is not a rotation (not orthonormal, or a quaternion not of unit length)");
    poses.push_back(T);
  }
  if (poses.empty()) throw InputError(path + ": no poses in the file");
  return poses;
}

std::vector<PosedScan> loadPosedScans(const std::string& scans_dir, const std::string& pose_file) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(scans_dir, ec)) throw InputError(scans_dir + ": no such folder of scans");
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(scans_dir, ec)) {
    std::string ext = e.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (e.is_regular_file() && (ext == ".pcd" || ext == ".ply" || ext == ".xyz")) files.push_back(e.path().string());
  }
  std::sort(files.begin(), files.end(), namedBefore);
  const std::vector<Eigen::Matrix4d> poses = loadPoseSequence(pose_file);
  if (files.size() != poses.size())
    throw InputError(scans_dir + ": " + std::to_string(files.size()) + " scans (.pcd, .ply, .xyz), but " + pose_file +
                     " holds " + std::to_string(poses.size()) + " poses (one a scan, in the scans' name order)");
  std::vector<PosedScan> scans(files.size());
  for (size_t i = 0; i < files.size(); ++i) scans[i] = {loadMap(files[i]), poses[i]};
  return scans;
}

}  // namespace tomomap
