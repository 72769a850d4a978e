// The fleet's map as a user finds it: built by a daemon from the slices it
// holds (its own and those its peers sent for matching), in files beside
// transforms.json and on ROS 2's /fleet_map and /fleet_map_grid, read by a
// ROS 2 node of the other DDS vendor, early or late; and following a map
// update. One robot's map comes from octomap_server's topic.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <future>
#include <unordered_set>

#include <octomap/OcTree.h>

#include "cyclone_reader.hpp"
#include "fleet.hpp"
#include "fleet_map_truth.hpp"

using namespace tomomap;
using namespace tomomap::test;
using namespace std::chrono_literals;

namespace {

constexpr double kGrid = 0.1;

/// Robots in `id`'s last fleet map (status.json), 0 before the first or
/// while it is not current (a build is running or due).
size_t robotsInFleetMap(const Fleet& fleet, const std::string& id) {
  const auto status = fleet.readJson(id, "status.json");
  if (!status.contains("fleet_map") || !status["fleet_map"].contains("robots") ||
      !status["fleet_map"].value("current", false))
    return 0;
  return status["fleet_map"]["robots"].size();
}

/// A pillar 0.3 m square standing 2 m on a map's lowest floor, at the first
/// spot near its middle where nothing stands within 0.5 m: new where it stands.
Points pillarFor(const Points& map) {
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(INFINITY), hi = -lo;
  for (const auto& p : map) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const float floor = lo.z(), top = lo.z() + 2.0f;
  const Eigen::Vector2f mid = (lo + hi).head<2>() / 2;
  for (float r = 0; r < 10; r += 0.25f)
    for (float a = 0; a < 6.3f; a += 0.5f) {
      const Eigen::Vector2f at = mid + r * Eigen::Vector2f(std::cos(a), std::sin(a));
      const bool clear = std::none_of(map.begin(), map.end(), [&](const Eigen::Vector3f& p) {
        return p.z() > floor + 0.3f && p.z() < top && (p.head<2>() - at).norm() < 0.5f;
      });
      if (!clear) continue;
      Points pillar;
      for (float z = floor + 0.3f; z <= top; z += 0.03f)
        for (float x = -0.15f; x <= 0.15f; x += 0.03f)
          for (float y = -0.15f; y <= 0.15f; y += 0.03f) pillar.emplace_back(at.x() + x, at.y() + y, z);
      return pillar;
    }
  return {};
}

/// How many of `pillar`'s points, placed by `T`, lie within one cell of a cell of `merged`.
double shareCovered(const Points& merged, const Points& pillar, const Eigen::Matrix4d& T) {
  std::unordered_set<uint64_t> cells;
  for (const auto& p : merged) cells.insert(latticeKey(p, kGrid));
  size_t covered = 0;
  for (const auto& q : pillar)
    covered += nearACell(
        cells, (T.topLeftCorner<3, 3>() * q.cast<double>() + T.topRightCorner<3, 1>()).cast<float>(), kGrid);
  return pillar.empty() ? 0.0 : static_cast<double>(covered) / static_cast<double>(pillar.size());
}

/// `map` as octomap_server publishes it on /octomap_binary: an OcTree of
/// `resolution`, its binary data (OcTree::writeBinaryData) written to `path`.
void writeOctomapData(const std::string& path, const Points& map, double resolution) {
  octomap::OcTree tree(resolution);
  for (const auto& p : map) tree.updateNode(octomap::point3d(p.x(), p.y(), p.z()), true);
  std::ofstream out(path, std::ios::binary);
  ASSERT_TRUE(tree.writeBinaryData(out));
}

}  // namespace

TEST(FleetMap, ADaemonMergesTheSlicesItHoldsNearTheTruthForRos2ReadersEarlyAndLateAndFollowsAnUpdate) {
  TempDir dir;
  const std::string world = dir / "w";
  const auto gen = runTomomap("synth -o " + world + " -n 3 -s 5 --scale 0.5");
  ASSERT_EQ(gen.exit_code, 0) << gen.output;
  // charlie's map where the test can rewrite it.
  const Points charlie_map = loadMap(world + "/map_2.pcd");
  savePcd(dir / "charlie.pcd", charlie_map);
  const int domain = 100 + static_cast<int>(::getpid() % 100);
  Fleet fleet(dir);
  std::vector<AgentSpec> agents{
      {"alpha", world + "/map_0.pcd", kGrid}, {"bravo", "", kGrid}, {"charlie", dir / "charlie.pcd", kGrid}};
  // alpha builds the map as often as allowed and publishes it; bravo reads
  // its own map from octomap_server's topic and publishes no fleet map (one publisher).
  const std::string ros2 = "[ros2]\ndomain = " + std::to_string(domain) + "\n";
  agents[0].extra = ros2 + "[fleet_map]\ninterval_s = 1\n";
  agents[1].extra = ros2 + "map_topic = \"/bravo/octomap_binary\"\nmap_type = \"octomap_msgs/Octomap\"\n" +
                    "[fleet_map]\nenabled = false\n";
  writeOctomapData(dir / "bravo.octomap", loadMap(world + "/map_1.pcd"), 0.05);
  // A node that joined before the map existed: it gets each new map as published.
  auto early = std::async(std::launch::async, [&] {
    std::string output;
    nlohmann::json got = readWithCyclone(kJazzyLocalhost, "fleet_map", domain, "3", output, 600);
    return std::make_pair(got, output);
  });
  for (const auto& a : agents) fleet.start(a, agents);
  const std::vector<std::string> ids{"alpha", "bravo", "charlie"};
  const auto octomap = runBinary("env", "CYCLONEDDS_URI='" + kJazzyLocalhost.cyclonedds_uri +
                                            "' " CYCLONE_CLOUD_PUBLISHER_BIN " " + std::to_string(domain) +
                                            " /bravo/octomap_binary " + (dir / "bravo.octomap") +
                                            " octomap-binary@0.05 bravo_odom 120");
  ASSERT_EQ(octomap.exit_code, 0) << octomap.output << fleet.log("bravo");
  // Every pair agreed and the map built from the frame they make: nothing changes it after.
  ASSERT_TRUE(fleet.waitForTransforms(ids, 3, 600s)) << fleet.log("alpha");
  ASSERT_TRUE(Fleet::waitFor([&] { return robotsInFleetMap(fleet, "alpha") == 3; }, 300s))
      << fleet.readJson("alpha", "status.json").dump(2) << fleet.log("alpha");

  // The files: every cell where the maps merged by their true poses have one.
  const auto status = fleet.readJson("alpha", "status.json")["fleet_map"];
  const Points merged = loadMap(dir / "out-alpha/fleet_map.pcd");
  const double share = shareNearTheTruth(world, merged, 3, kGrid);
  std::printf("alpha's fleet map: %zu cells, %.4f of them within one cell of the maps merged by their true poses\n",
              merged.size(), share);
  EXPECT_GE(share, 0.95);
  EXPECT_EQ(merged.size(), status["cells"].get<size_t>());
  EXPECT_EQ(status["published"], nlohmann::json({"/fleet_map", "/fleet_map_grid"})) << status.dump(2);
  for (const auto& r : status["robots"]) {
    EXPECT_GT(r["cells"].get<size_t>(), 1000u) << r.dump();
    EXPECT_EQ(r["slices_as_features"].get<int>(), 0) << "every slice of this world crosses as occupancy";
  }
  EXPECT_NE(readText(dir / "out-alpha/fleet_map.yaml").find("image: fleet_map.pgm"), std::string::npos);
  EXPECT_GT(std::filesystem::file_size(dir / "out-alpha/fleet_map.png"), 10'000u);
  EXPECT_NE(fleet.log("alpha").find("fleet map: "), std::string::npos) << fleet.log("alpha");
  const auto shown = runTomomap("status " + (dir / "out-alpha"));
  EXPECT_NE(shown.output.find("fleet map " + std::to_string(merged.size()) + " cells in alpha's frame, levelled"),
            std::string::npos)
      << shown.output;
  EXPECT_NE(fleet.log("bravo").find("(octomap_msgs/Octomap)"), std::string::npos) << fleet.log("bravo");
  EXPECT_EQ(fleet.readJson("bravo", "status.json")["map"]["frame_id"], "bravo_odom");
  // Every daemon builds it (without ROS 2: the files).
  EXPECT_TRUE(Fleet::waitFor([&] { return robotsInFleetMap(fleet, "charlie") == 3; }, 120s))
      << fleet.readJson("charlie", "status.json").dump(2);

  // The other DDS vendor's node that was there first, and one that comes now.
  const auto [first, first_output] = early.get();
  ASSERT_FALSE(first.is_null()) << first_output;
  EXPECT_EQ(first["frame_id"], "alpha/map") << first_output;
  EXPECT_EQ(first["point_step"], 20) << first_output;
  std::string output;
  const nlohmann::json cloud = readWithCyclone(kJazzyLocalhost, "fleet_map", domain, "3", output);
  ASSERT_FALSE(cloud.is_null()) << output;
  const nlohmann::json grid = readWithCyclone(kJazzyLocalhost, "fleet_map_grid", domain, "1", output);
  ASSERT_FALSE(grid.is_null()) << output;
  const auto now = fleet.readJson("alpha", "status.json")["fleet_map"];
  EXPECT_EQ(cloud["width"].get<size_t>(), now["cells"].get<size_t>()) << output;
  size_t labelled = 0;
  for (const auto& n : cloud["per_label"]) labelled += n.get<size_t>();
  EXPECT_EQ(labelled, cloud["width"].get<size_t>()) << "every point is labelled by its robot";
  EXPECT_EQ(grid["frame_id"], "alpha/map") << output;
  EXPECT_NEAR(grid["resolution"].get<double>(), kGrid, 1e-6);
  EXPECT_EQ(grid["width"].get<int>(), now["grid"]["width"].get<int>());
  EXPECT_EQ(grid["occupied"].get<size_t>() + grid["unknown"].get<size_t>(), grid["cells"].get<size_t>())
      << "occupied or unknown: slices carry no free space";
  EXPECT_GT(grid["occupied"].get<size_t>(), grid["cells"].get<size_t>() / 50) << "the building's walls";
  // The type hashes Jazzy's nodes carry (`ros2 topic info -v`; PointCloud2's is rcl's own test's).
  EXPECT_EQ(cloud["user_data"], "typehash=RIHS01_9198cabf7da3796ae6fe19c4cb3bdd3525492988c70522628af5daa124bae2b5;");
  EXPECT_EQ(grid["user_data"], "typehash=RIHS01_8d348150c12913a31ee0ec170fbf25089e4745d17035792a1ba94d6f0bc0cfc7;");

  // Under each ROS 2 discovery setting that keeps nodes on the robot (the
  // daemon's default, localhost_only), as for /tf_static.
  for (const Ros2Setting& setting : {kHumbleLocalhostOnly, kJazzySubnetStaticPeer}) {
    SCOPED_TRACE(setting.name);
    EXPECT_EQ(readWithCyclone(setting, "fleet_map_grid", domain, "1", output).value("width", 0),
              now["grid"]["width"].get<int>())
        << output;
  }

  // charlie's robot maps a pillar: the fleet's map follows.
  const Points pillar = pillarFor(charlie_map);
  ASSERT_FALSE(pillar.empty());
  const Eigen::Matrix4d T_alpha_charlie = truthOf(world, 2);
  EXPECT_LT(shareCovered(merged, pillar, T_alpha_charlie), 0.5) << "no pillar yet";
  Points updated = charlie_map;
  updated.insert(updated.end(), pillar.begin(), pillar.end());
  savePcd(dir / "charlie.pcd.tmp", updated);
  std::filesystem::rename(dir / "charlie.pcd.tmp", dir / "charlie.pcd");
  double covered = 0;
  EXPECT_TRUE(Fleet::waitFor(
      [&] {
        covered = shareCovered(loadMap(dir / "out-alpha/fleet_map.pcd"), pillar, T_alpha_charlie);
        return covered > 0.9;
      },
      300s))
      << covered << "\n"
      << fleet.log("alpha");
  stopAll(fleet, ids);
}
