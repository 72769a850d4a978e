// `tomomap merge`: the fleet's map from robots' maps, as a user reads it back.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "fleet_map_truth.hpp"
#include "results/agreed_transform.hpp"

using namespace tomomap;
using namespace tomomap::test;

namespace {

constexpr double kGrid = 0.1;

/// Map i's pose in map 0's frame.
Eigen::Matrix4d truthOf(const TempDir& dir, int i) { return test::truthOf(dir / "w", i); }

double shareNearTheTruth(const TempDir& dir, const Points& merged, int maps) {
  return test::shareNearTheTruth(dir / "w", merged, maps, kGrid);
}

void synthThree(const TempDir& dir) {
  const auto gen = runTomomap("synth -o " + (dir / "w") + " -n 3 -s 5 --scale 0.5");
  ASSERT_EQ(gen.exit_code, 0) << gen.output;
}

std::string threeMaps(const TempDir& dir) {
  return "alpha=" + (dir / "w/map_0.pcd") + " bravo=" + (dir / "w/map_1.pcd") + " charlie=" + (dir / "w/map_2.pcd");
}

}  // namespace

TEST(Merge, ThreeRobotsMapsMatchedHereLieWithinACellOfTheTruthAndEveryFileReadsBack) {
  TempDir dir;
  synthThree(dir);
  if (HasFailure()) return;
  const auto run = runTomomap("merge " + threeMaps(dir) + " -g 0.1 -o " + (dir / "m"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("pair             alpha<-bravo: x "), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("in alpha's frame"), std::string::npos) << run.output;

  const Points merged = loadMap(dir / "m/fleet_map.pcd");
  const double share = shareNearTheTruth(dir, merged, 3);
  std::printf("merged %zu cells, %.4f of them within one cell of the maps merged by their true poses\n", merged.size(),
              share);
  EXPECT_GE(share, 0.95);
  // Each robot's cells can be told apart: PCL's PointXYZRGBL, a colour and a label per point.
  const std::string pcd = readText(dir / "m/fleet_map.pcd");
  EXPECT_NE(pcd.find("FIELDS x y z rgba label"), std::string::npos) << pcd.substr(0, 300);

  // The 2D grid as map_server reads it: a PGM and its YAML.
  const std::string yaml = readText(dir / "m/fleet_map.yaml");
  EXPECT_NE(yaml.find("image: fleet_map.pgm"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("resolution: 0.1\n"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("mode: trinary"), std::string::npos) << yaml;
  std::ifstream pgm(dir / "m/fleet_map.pgm", std::ios::binary);
  std::string magic;
  int width = 0, height = 0, depth = 0;
  pgm >> magic >> width >> height >> depth;
  pgm.get();
  EXPECT_EQ(magic, "P5");
  EXPECT_EQ(depth, 255);
  ASSERT_GT(width * height, 100);
  std::string pixels(static_cast<size_t>(width) * static_cast<size_t>(height), '\0');
  ASSERT_TRUE(pgm.read(pixels.data(), static_cast<std::streamsize>(pixels.size()))) << "the whole image is there";
  const size_t occupied = countOf(pixels, std::string(1, '\0')), unknown = countOf(pixels, std::string(1, '\xcd'));
  EXPECT_EQ(occupied + unknown, pixels.size()) << "occupied or unknown: the slices do not carry free space";
  EXPECT_GT(occupied, pixels.size() / 50) << "the building's walls";
  EXPECT_GT(std::filesystem::file_size(dir / "m/fleet_map.png"), 10'000u);
}

TEST(Merge, ADaemonsFrameFilePlacesTheMapsItKnowsAndTheOthersAreLeftOutAndSaid) {
  TempDir dir;
  synthThree(dir);
  if (HasFailure()) return;
  // frame.json as a daemon writes it (docs/json.md), for alpha and bravo only.
  nlohmann::json frame{{"reference", "alpha"}, {"agents", nlohmann::json::array()}};
  for (int i = 0; i < 2; ++i)
    frame["agents"].push_back({{"agent", i == 0 ? "alpha" : "bravo"},
                               {"T_reference_agent_6dof", matrixJson(truthOf(dir, i))},
                               {"path", {"alpha"}}});
  std::ofstream(dir / "frame.json") << frame.dump(2);
  const auto run =
      runTomomap("merge " + threeMaps(dir) + " -g 0.1 --frame " + (dir / "frame.json") + " -o " + (dir / "m"));
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("charlie's map is not placed in alpha's frame"), std::string::npos) << run.output;
  EXPECT_EQ(run.output.find("pair "), std::string::npos) << "nothing matched here\n" << run.output;
  EXPECT_GE(shareNearTheTruth(dir, loadMap(dir / "m/fleet_map.pcd"), 2), 0.99) << "placed by the truth itself";

  // Bad input: said, nothing written.
  std::ofstream(dir / "broken.json") << "{\"reference\": \"alpha\"}";
  const auto broken =
      runTomomap("merge " + threeMaps(dir) + " --frame " + (dir / "broken.json") + " -o " + (dir / "m2"));
  EXPECT_EQ(broken.exit_code, 2) << broken.output;
  EXPECT_NE(broken.output.find("not a frame.json"), std::string::npos) << broken.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "m2/fleet_map.pcd"));
  const auto twice = runTomomap("merge " + (dir / "w/map_0.pcd") + " " + (dir / "w/map_0.pcd") + " -o " + (dir / "m3"));
  EXPECT_EQ(twice.exit_code, 2) << twice.output;
  EXPECT_NE(twice.output.find("two maps are named map_0"), std::string::npos) << twice.output;
  const auto band = runTomomap("merge " + threeMaps(dir) + " --band 2,1 -o " + (dir / "m4"));
  EXPECT_EQ(band.exit_code, 2) << band.output;
  EXPECT_NE(band.output.find("--band must be LOW,HIGH"), std::string::npos) << band.output;
}
