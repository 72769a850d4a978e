#pragma once
// Helpers shared by the test programs: data paths, temporary directories, running the CLI, timing.
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>
#include <string>

#include "io/map_io.hpp"

namespace tomomap::test {

/// How long f() takes [s] (the benchmarks').
template <typename F>
double secondsOf(F&& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

inline std::string demoRoom() { return TOMOMAP_DEMO_ROOM; }
inline bool haveDemoRoom() { return std::filesystem::exists(demoRoom() + "/demo-pcd1.pcd"); }
/// The real sensor scans beside demo-room (../shared/data/real-scans).
inline std::string realScans() { return demoRoom() + "/../real-scans"; }
/// The posed SLAM sequences beside them (../shared/data/slam-sequences).
inline std::string slamSequences() { return demoRoom() + "/../slam-sequences"; }

#define REQUIRE_DEMO_ROOM()             \
  if (!::tomomap::test::haveDemoRoom()) \
  GTEST_SKIP() << "demo-room data set not found at " << ::tomomap::test::demoRoom()

/// A whole file as text; empty if it cannot be read.
inline std::string readText(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Occurrences of `what` in `text` (e.g. log lines with a word).
inline size_t countOf(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

/// A fresh directory removed when the object goes out of scope.
/// The top-level fields docs/json.md lists for one document: the rows
/// "| `field` |" of the table under the heading that contains `section`.
inline std::set<std::string> documentedJsonFields(const std::string& section) {
  std::ifstream in(std::string(TOMOMAP_SOURCE_DIR) + "/docs/json.md");
  std::set<std::string> fields;
  bool inside = false;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("## ", 0) == 0) inside = line.find(section) != std::string::npos;
    if (inside && line.rfind("| `", 0) == 0) fields.insert(line.substr(3, line.find('`', 3) - 3));
  }
  return fields;
}

/// The keys of a JSON object, as text.
template <typename Json>
std::set<std::string> keysOf(const Json& object) {
  std::set<std::string> keys;
  for (const auto& [key, value] : object.items()) keys.insert(key);
  return keys;
}

struct TempDir {
  std::filesystem::path path;
  TempDir() {
    std::random_device rd;
    path = std::filesystem::temp_directory_path() / ("tomomap-test-" + std::to_string(rd()) + std::to_string(rd()));
    std::filesystem::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  std::string operator/(const std::string& name) const { return (path / name).string(); }
};

struct CommandResult {
  int exit_code = -1;
  std::string output;  ///< stdout and stderr together
};

/// Runs `binary` with `args` (shell syntax) and captures its output.
inline CommandResult runBinary(const std::string& binary, const std::string& args) {
  CommandResult r;
  const std::string cmd = binary + " " + args + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buf;
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) r.output.append(buf.data(), n);
  const int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

inline CommandResult runTomomap(const std::string& args) { return runBinary(TOMOMAP_BIN, args); }

/// The expected T_target_source from two ground-truth pose files (3x4
/// row-major, world to map): P_target * P_source^-1, the demo-room and synth convention.
inline Pose4 groundTruth(const std::string& target_pose, const std::string& source_pose) {
  return Pose4::fromMatrix(loadPoseFile(target_pose) * loadPoseFile(source_pose).inverse());
}

/// Demo-room maps and the expected T_1_2 (target pcd1, source pcd2).
struct DemoPair {
  Points map1, map2;
  Pose4 T_1_2;
};

inline DemoPair loadDemoPair() {
  const std::string d = demoRoom() + "/";
  DemoPair p{loadMap(d + "demo-pcd1.pcd"), loadMap(d + "demo-pcd2.pcd"), {}};
  p.T_1_2 = groundTruth(d + "demo-pcd1-gtpose.txt", d + "demo-pcd2-gtpose.txt");
  return p;
}

/// `map` after the robot mapped a cabinet in the middle of the room: three
/// 0.6 x 0.8 m panels of points 0.4-1.2 m above the floor, inside the map's
/// bounds, so a map update that changes only some slices.
inline Points withCabinet(const Points& map) {
  Points updated = map;
  Eigen::Vector3f lo = map.front(), hi = map.front();
  for (const auto& p : map) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const Eigen::Vector3f c = (lo + hi) / 2;
  for (float u = -0.3f; u <= 0.3f; u += 0.01f)
    for (float z = 0.4f; z <= 1.2f; z += 0.01f) {
      updated.emplace_back(c.x() + u, c.y() - 0.25f, lo.z() + z);
      updated.emplace_back(c.x() + u, c.y() + 0.25f, lo.z() + z);
      updated.emplace_back(c.x() - 0.3f, c.y() + u * 0.8f, lo.z() + z);
    }
  return updated;
}

}  // namespace tomomap::test
