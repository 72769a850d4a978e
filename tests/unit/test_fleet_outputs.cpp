// What leaves the daemon when the agreed transforms change (FleetOutputs):
// the files an operator reads and the tree ROS 2 gets, without DDS.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "config.hpp"
#include "fleet_outputs.hpp"
#include "support.hpp"

using namespace tomomap;
using namespace tomomap::daemon;

namespace {

Config fleetConfig(const test::TempDir& dir, const std::string& out) {
  std::ofstream(dir / "c.toml") << "agent = \"alpha\"\nmap = \"a.pcd\"\ndiscovery_port = 17500\noutput_dir = \"" << out
                                << "\"\n[[peer]]\nid = \"bravo\"\nhost = \"10.0.0.2\"\nport = 17600\n[ros2]\n";
  return loadConfig(dir / "c.toml");
}

AgreedTransform alphaBravo(double x) {
  AgreedTransform t;
  t.target = "alpha";
  t.source = "bravo";
  t.reliable = true;
  t.T_target_source = {x, 2, 0.5, 0.3};
  t.lead_sigma = 12;
  t.computed_by = "alpha";
  t.computed_at_ms = 1'700'000'000'000;
  return t;
}

nlohmann::json readJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

}  // namespace

TEST(FleetOutputs, TheFilesHoldTheFrameAndTheTreeIsHandedOnOnlyWhenItChanges) {
  test::TempDir dir;
  const std::string out = dir / "out";
  std::filesystem::create_directories(out);
  const Config config = fleetConfig(dir, out);
  Log log(LogLevel::Error);
  FleetOutputs outputs(log);
  std::vector<std::vector<transport::TfFrame>> handed;
  outputs.setTreePublisher([&](const auto& frames) { handed.push_back(frames); });

  outputs.update({alphaBravo(1)}, config);
  EXPECT_FALSE(outputs.unwritten());
  EXPECT_EQ(readJson(out + "/transforms.json")["transforms"].size(), 1u);
  const auto frame = readJson(out + "/frame.json");
  EXPECT_EQ(frame["reference"], "alpha");
  ASSERT_EQ(handed.size(), 1u);
  ASSERT_EQ(handed[0].size(), 1u);
  EXPECT_EQ(handed[0][0].parent, "alpha/map");
  EXPECT_EQ(handed[0][0].child, "bravo/map");
  EXPECT_NEAR(handed[0][0].T_parent_child(0, 3), 1.0, 1e-9) << "bravo's pose in alpha's frame";

  outputs.update({alphaBravo(1)}, config);
  EXPECT_EQ(handed.size(), 1u) << "the same tree is not handed on again";
  outputs.update({alphaBravo(1.5)}, config);
  ASSERT_EQ(handed.size(), 2u);
  EXPECT_NEAR(handed[1][0].T_parent_child(0, 3), 1.5, 1e-9);
  // A new publisher (a ROS 2 node started again) gets the whole tree at once.
  outputs.setTreePublisher([&](const auto& frames) { handed.push_back(frames); });
  outputs.update({alphaBravo(1.5)}, config);
  EXPECT_EQ(handed.size(), 3u);

  // Bravo's map leaned 8 degrees and was levelled before slicing: tf carries
  // the transform between the maps' own frames, the lean included.
  AgreedTransform leaning = alphaBravo(1.5);
  const Eigen::AngleAxisd lean(radians(8), Eigen::Vector3d(1, 1, 0).normalized());
  leaning.source_up = lean.inverse() * Eigen::Vector3d::UnitZ();  // its up, in its own (leaning) frame
  outputs.update({leaning}, config);
  ASSERT_EQ(handed.size(), 4u) << "a new up is a new tree";
  const Eigen::Matrix4d T = handed[3][0].T_parent_child;
  const Eigen::Vector3d bravo_up = leaning.source_up;
  EXPECT_TRUE((T.topLeftCorner<3, 3>() * bravo_up).isApprox(Eigen::Vector3d::UnitZ(), 1e-9))
      << "bravo's up lands on alpha's\n"
      << T;
  EXPECT_TRUE(T.isApprox(leaning.ownFrames(), 1e-12)) << T;
  const auto agent = readJson(out + "/frame.json")["agents"][1];
  EXPECT_EQ(agent["agent"], "bravo");
  EXPECT_NEAR(agent["up"][0].get<double>(), bravo_up.x(), 1e-12);
  EXPECT_NEAR(agent["T_reference_agent_6dof"][0][3].get<double>(), 1.5, 1e-9);

  // Under a world frame (map_merge_3d's convention) every map hangs from it, the root's as the identity.
  Config under_world = config;
  under_world.ros2.world = "world";
  outputs.setTreePublisher([&](const auto& frames) { handed.push_back(frames); });
  outputs.update({leaning}, under_world);
  ASSERT_EQ(handed.size(), 5u);
  ASSERT_EQ(handed[4].size(), 2u);
  EXPECT_EQ(handed[4][0].parent, "world");
  EXPECT_EQ(handed[4][0].child, "alpha/map");
  EXPECT_TRUE(handed[4][0].T_parent_child.isIdentity(0.0));
  EXPECT_EQ(handed[4][1].parent, "world");
  EXPECT_EQ(handed[4][1].child, "bravo/map");
  EXPECT_TRUE(handed[4][1].T_parent_child.isApprox(T, 1e-12)) << "bravo's pose in the root's map";
}

TEST(FleetOutputs, AFailedWriteIsSaidAndRetriedUntilItWorks) {
  test::TempDir dir;
  const std::string out = dir / "out";
  std::ofstream(out) << "a file where the output folder should be";
  const Config config = fleetConfig(dir, out);
  Log log(LogLevel::Error);
  FleetOutputs outputs(log);
  outputs.update({alphaBravo(1)}, config);
  EXPECT_TRUE(outputs.unwritten());
  EXPECT_FALSE(outputs.writeError().empty());
  EXPECT_EQ(outputs.frame().poses.size(), 2u) << "the frame is built all the same";

  std::filesystem::remove(out);
  std::filesystem::create_directories(out);
  outputs.retry(config);
  EXPECT_FALSE(outputs.unwritten());
  EXPECT_TRUE(outputs.writeError().empty());
  EXPECT_EQ(readJson(out + "/transforms.json")["transforms"].size(), 1u) << "the transforms of the failed write";
}
