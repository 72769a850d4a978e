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

TEST(GravityStability, AHallLeaningBeyondTheFloorsConeIsLevelledByItsFloorsNeverByItsWalls) {
  // Beyond kClassCone a map's walls may pass for its floors: the hall on its
  // side reads 7-48 deg off its walls, as tightly as it reads its floors when
  // it leans. What is levelled there is what its lines (posts, door frames,
  // corners) stand along.
  const std::string dir = test::slamSequences() + "/hku-main-building";
  if (!std::filesystem::exists(dir)) GTEST_SKIP() << "no SLAM sequences at " << test::slamSequences();
  const auto scans = loadPosedScans(dir + "/scans", dir + "/optimized_poses.txt");
  const Points saved = synth::accumulate(scans, 0, scans.size() / 2, synth::SequencePairParams{});
  const Points hall = rotatePoints(saved, estimateTilt(saved, 0.1).leveling());
  const auto turned = [&](double deg, double axis_deg) {
    const Eigen::Vector3d axis(std::cos(radians(axis_deg)), std::sin(radians(axis_deg)), 0.0);
    return Eigen::Quaterniond(Eigen::AngleAxisd(radians(deg), axis));
  };
  for (const double axis : {0.0, 60.0}) {
    for (const double deg : {35.0, 40.0}) {
      SCOPED_TRACE("leaning " + std::to_string(deg) + " deg about " + std::to_string(axis));
      const Eigen::Quaterniond q = turned(deg, axis);
      const Tilt t = estimateTilt(rotatePoints(hall, q), 0.1);
      EXPECT_TRUE(t.levelable()) << leanText(t) << ", " << t.standing_lines << " of " << t.lines << " lines standing";
      EXPECT_LT(degrees(std::acos(std::clamp(t.up.dot(q * Eigen::Vector3d::UnitZ()), -1.0, 1.0))), 1.0) << leanText(t);
    }
  }
  size_t beyond = 0;
  for (const double axis : {0.0, 60.0})
    for (const double deg : {60.0, 70.0, 80.0, 90.0}) {
      SCOPED_TRACE("on its side, " + std::to_string(deg) + " deg about " + std::to_string(axis));
      const Tilt t = estimateTilt(rotatePoints(hall, turned(deg, axis)), 0.1);
      std::cout << "on its side " << deg << " deg about " << axis << ": " << leanText(t) << ", " << t.standing_lines
                << " of " << t.lines << " lines standing\n";
      if (!t.measured || t.angle <= kClassCone) continue;  // within the cone only floors are read: not told apart
      ++beyond;
      EXPECT_FALSE(t.levelable()) << leanText(t) << ", " << t.standing_lines << " of " << t.lines << " lines standing";
    }
  EXPECT_GT(beyond, 0u) << "no turn read its walls beyond the cone: nothing checked";
}
