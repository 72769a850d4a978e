// The tilt estimate of every real map beside the checkout holds as a map is
// thinned (a sparser sensor) or cropped to half (another robot's part of the
// place): the lean it reads moves by less than the uncertainty it states, or
// the part cannot check it (fairPart: too few of the map's floors left in it
// to read them). Checked on thinnings and cuts the estimate does not make of
// itself (gravity.cpp's parts: every 3rd and 10th point from the first,
// halves at the median along 0, 45, 90 and 135 degrees).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <iostream>

#include "core/gravity.hpp"
#include "io/pose_sequence.hpp"
#include "support.hpp"
#include "synth/sequence_pairs.hpp"

using namespace tomomap;

namespace {

struct RealMap {
  std::string name;
  Points points;
  double grid;
};

/// Every real map there is: the rendered room pair, the three single scans,
/// and each SLAM sequence accumulated whole with its own poses.
std::vector<RealMap> realMaps() {
  std::vector<RealMap> maps;
  const auto add = [&](const std::string& path, double grid) {
    if (std::filesystem::exists(path)) maps.push_back({path, loadMap(path), grid});
  };
  add(test::demoRoom() + "/demo-pcd1.pcd", 0.05);
  add(test::demoRoom() + "/demo-pcd2.pcd", 0.05);
  add(test::realScans() + "/sunrgbd-000017.pcd", 0.05);
  add(test::realScans() + "/kitti-000008.pcd", 0.2);
  add(test::realScans() + "/nuscenes-lidar-top.pcd", 0.2);
  for (const char* sequence : {"hku-main-building", "hku-campus-1", "hku-campus-2"}) {
    const std::string dir = test::slamSequences() + "/" + sequence;
    if (!std::filesystem::exists(dir)) continue;
    const auto scans = loadPosedScans(dir + "/scans", dir + "/optimized_poses.txt");
    maps.push_back({dir, synth::accumulate(scans, 0, scans.size() - 1, synth::SequencePairParams{}), 0.1});
  }
  return maps;
}

/// Every `k`-th point from the second.
Points thinned(const Points& map, size_t k) {
  Points out;
  for (size_t i = 1; i < map.size(); i += k) out.push_back(map[i]);
  return out;
}

/// The half of `map` on one side of its median along direction `a` [rad].
Points half(const Points& map, double a, bool low) {
  const Eigen::Vector3f direction(static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a)), 0.0f);
  const auto along = [&](const Eigen::Vector3f& p) { return p.dot(direction); };
  std::vector<float> v;
  for (const auto& p : map) v.push_back(along(p));
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  const float median = v[v.size() / 2];
  Points out;
  for (const auto& p : map)
    if ((along(p) < median) == low) out.push_back(p);
  return out;
}

}  // namespace

TEST(GravityStability, ThinningAndCroppingMoveTheTiltByLessThanItsStatedUncertainty) {
  const std::vector<RealMap> maps = realMaps();
  if (maps.empty()) GTEST_SKIP() << "no real maps beside the checkout (" << test::demoRoom() << ")";
  for (const auto& m : maps) {
    SCOPED_TRACE(m.name);
    const Tilt whole = estimateTilt(m.points, m.grid);
    if (!whole.measured) continue;  // matched as it is: nothing to hold
    size_t checked = 0;
    std::vector<std::pair<std::string, Points>> parts;
    for (size_t k : {3, 5, 7, 10}) parts.emplace_back("one point in " + std::to_string(k), thinned(m.points, k));
    for (double deg : {22.5, 67.5, 112.5, 157.5})
      for (bool low : {true, false})
        parts.emplace_back("half along " + std::to_string(deg) + " deg, " + (low ? "low" : "high"),
                           half(m.points, radians(deg), low));
    for (const auto& [what, points] : parts) {
      const Tilt t = estimateTilt(points, m.grid);
      if (!fairPart(t, whole)) continue;
      ++checked;
      const double moved = std::acos(std::clamp(t.up.dot(whole.up), -1.0, 1.0));
      EXPECT_LE(degrees(moved), degrees(whole.uncertainty))
          << what << ": its up lies " << degrees(moved) << " deg from the whole map's, which reads "
          << degrees(whole.angle) << " +- " << degrees(whole.uncertainty);
    }
    std::cout << m.name << ": " << degrees(whole.angle) << " +- " << degrees(whole.uncertainty) << " deg, " << checked
              << " of " << parts.size() << " parts checked it\n";
  }
}
