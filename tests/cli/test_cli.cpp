// The `tomomap` binary as a user runs it: exit codes, messages, files.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <regex>
#include <set>

#include "results/json_schema.hpp"
#include "support.hpp"

using namespace tomomap;
using tomomap::test::documentedJsonFields;
using tomomap::test::keysOf;
using tomomap::test::readText;
using tomomap::test::runTomomap;
using tomomap::test::TempDir;

namespace {

std::string demo(const std::string& f) { return test::demoRoom() + "/" + f; }
std::string demoMatchArgs() {
  return "match " + demo("demo-pcd1.pcd") + " " + demo("demo-pcd2.pcd") + " --gt-target " +
         demo("demo-pcd1-gtpose.txt") + " --gt-source " + demo("demo-pcd2-gtpose.txt");
}

size_t lines(const std::string& s) { return static_cast<size_t>(std::count(s.begin(), s.end(), '\n')); }

/// A bad-input run: exit code 2, one line naming `what`, and no transform printed.
void expectBadInput(const test::CommandResult& r, const std::string& what) {
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(what), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("T_target_source"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("Segmentation"), std::string::npos);
}

}  // namespace

TEST(Cli, HelpAndVersion) {
  const auto help = runTomomap("--help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.output.find("match"), std::string::npos);
  EXPECT_NE(help.output.find("synth"), std::string::npos);
  EXPECT_NE(help.output.find("Exit codes"), std::string::npos);
  const auto version = runTomomap("--version");
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_NE(version.output.find("tomomap 0."), std::string::npos);
  EXPECT_EQ(runTomomap("match --help").exit_code, 0);
  EXPECT_EQ(runTomomap("").exit_code, 2);            // no subcommand
  EXPECT_EQ(runTomomap("frobnicate").exit_code, 2);  // unknown subcommand
}

TEST(Cli, MatchDemoRoomPrintsTransformErrorAndJson) {
  REQUIRE_DEMO_ROOM();
  TempDir dir;
  const auto r = runTomomap(demoMatchArgs() + " --json " + (dir / "r.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("T_target_source"), std::string::npos);
  EXPECT_NE(r.output.find("ground truth"), std::string::npos);
  EXPECT_NE(r.output.find(": success"), std::string::npos);
  std::ifstream in(dir / "r.json");
  const auto j = nlohmann::json::parse(in);
  EXPECT_TRUE(j["reliable"].get<bool>());
  EXPECT_NEAR(j["T_target_source"]["x"].get<double>(), 0.978, 0.05);
  EXPECT_NEAR(j["T_target_source"]["yaw"].get<double>(), -3.087, 0.02);
  EXPECT_EQ(j["T_target_source"]["matrix"].size(), 4u);
  EXPECT_TRUE(j["error"]["success"].get<bool>());
  EXPECT_GT(j["features"]["support"].get<int>(), 3);
  // The pair's weight in the pose graph: the decision's lead, in standard deviations.
  EXPECT_GT(j["lead_sigma"].get<double>(), 0.0);
  EXPECT_EQ(j["lead_sigma"], j["candidate_decision"]["lead_sigma"]);
}

TEST(Cli, MissingFile) { expectBadInput(runTomomap("match /nonexistent/a.pcd /nonexistent/b.pcd"), "no such file"); }

TEST(Cli, NonFinitePointsAreDroppedCountedAndChangeNothing) {
  // An organised cloud from a PCL-based SLAM carries NaN rows: a normal map.
  REQUIRE_DEMO_ROOM();
  TempDir dir;
  Points map = loadMap(demo("demo-pcd2.pcd"));
  const Points clean = map;
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  for (size_t i = 0; i < 100; ++i)
    map.insert(map.begin() + static_cast<long>(i * (map.size() / 100)),
               i % 2 ? Eigen::Vector3f(nan, nan, nan) : Eigen::Vector3f(1, inf, 0));
  savePcd(dir / "with-nan.pcd", map);
  savePcd(dir / "clean.pcd", clean);
  const auto with =
      runTomomap("match --json " + (dir / "with.json") + " " + demo("demo-pcd1.pcd") + " " + (dir / "with-nan.pcd"));
  ASSERT_EQ(with.exit_code, 0) << with.output;
  EXPECT_NE(with.output.find("dropped 100 points with NaN or infinite coordinates"), std::string::npos) << with.output;
  const auto without =
      runTomomap("match --json " + (dir / "without.json") + " " + demo("demo-pcd1.pcd") + " " + (dir / "clean.pcd"));
  ASSERT_EQ(without.exit_code, 0) << without.output;
  const auto a = nlohmann::json::parse(std::ifstream(dir / "with.json"));
  const auto b = nlohmann::json::parse(std::ifstream(dir / "without.json"));
  EXPECT_EQ(a["T_target_source"], b["T_target_source"]) << "the same transform as without them";
  EXPECT_EQ(a["source_nonfinite_dropped"], 100);
  EXPECT_EQ(a["source_points"], clean.size());
}

TEST(Cli, AStrayPointFarAwayChangesNothing) {
  // One stray return 100 m from a room-sized map once stretched the raster
  // twenty-fold and left no slice dense enough to match (exit 1).
  REQUIRE_DEMO_ROOM();
  TempDir dir;
  Points map = loadMap(demo("demo-pcd2.pcd"));
  savePcd(dir / "clean.pcd", map);
  map.emplace_back(map.front() + Eigen::Vector3f(100, 0, 0));
  savePcd(dir / "stray.pcd", map);
  const auto with =
      runTomomap("match --json " + (dir / "with.json") + " " + demo("demo-pcd1.pcd") + " " + (dir / "stray.pcd"));
  ASSERT_EQ(with.exit_code, 0) << with.output;
  EXPECT_NE(with.output.find("left out 1 stray voxels"), std::string::npos) << with.output;
  ASSERT_EQ(
      runTomomap("match --json " + (dir / "without.json") + " " + demo("demo-pcd1.pcd") + " " + (dir / "clean.pcd"))
          .exit_code,
      0);
  const auto a = nlohmann::json::parse(std::ifstream(dir / "with.json"));
  const auto b = nlohmann::json::parse(std::ifstream(dir / "without.json"));
  EXPECT_EQ(a["T_target_source"], b["T_target_source"]) << "the same transform as without it";
  EXPECT_EQ(a["source_stray_voxels"], 1);
  EXPECT_EQ(b["source_stray_voxels"], 0);
}

TEST(Cli, EmptyTinyNanTruncatedAndCorruptMaps) {
  REQUIRE_DEMO_ROOM();
  TempDir dir;
  const std::string good = demo("demo-pcd1.pcd");
  std::ofstream(dir / "empty.pcd").flush();
  std::string ten;
  for (int i = 0; i < 10; ++i) ten += std::to_string(i) + " 0 1\n";
  std::ofstream(dir / "ten.xyz") << ten;
  std::ifstream in(good, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  std::ofstream(dir / "cut.pcd", std::ios::binary) << bytes.substr(0, bytes.size() / 3);
  std::string corrupt = bytes;
  corrupt.replace(corrupt.find("FIELDS"), 6, "FIELXS");
  std::ofstream(dir / "corrupt.pcd", std::ios::binary) << corrupt;

  expectBadInput(runTomomap("match " + good + " " + (dir / "empty.pcd")), "empty");
  expectBadInput(runTomomap("match " + good + " " + (dir / "ten.xyz")), "only 10 points");
  std::string mostly_nan = ten;
  for (int i = 0; i < 300; ++i) mostly_nan += "nan nan nan\n";
  std::ofstream(dir / "mostly-nan.xyz") << mostly_nan;
  expectBadInput(runTomomap("match " + good + " " + (dir / "mostly-nan.xyz")),
                 "only 10 of 310 points are finite (the rest NaN or infinite)");
  expectBadInput(runTomomap("match " + good + " " + (dir / "cut.pcd")), "cut.pcd");
  expectBadInput(runTomomap("match " + good + " " + (dir / "corrupt.pcd")), "corrupt.pcd");
  // One line of diagnosis, not a dump.
  EXPECT_EQ(lines(runTomomap("match -q " + good + " " + (dir / "cut.pcd")).output), 1u);
}

TEST(Cli, BadGridValues) {
  REQUIRE_DEMO_ROOM();
  const std::string maps = " " + demo("demo-pcd1.pcd") + " " + demo("demo-pcd2.pcd");
  expectBadInput(runTomomap("match" + maps + " --grid 0"), "--grid");
  expectBadInput(runTomomap("match" + maps + " --grid -0.05"), "--grid");
  expectBadInput(runTomomap("match" + maps + " --grid abc"), "--grid");
  // One range for the grid everywhere (the daemon's `grid` key too).
  expectBadInput(runTomomap("match" + maps + " --grid 0.00001"), "from 0.005 to 10");
  expectBadInput(runTomomap("match" + maps + " --grid 50"), "from 0.005 to 10");
}

TEST(Cli, BadPoseFile) {
  REQUIRE_DEMO_ROOM();
  TempDir dir;
  std::ofstream(dir / "pose.txt") << "1 2 3\n";
  expectBadInput(runTomomap("match " + demo("demo-pcd1.pcd") + " " + demo("demo-pcd2.pcd") + " --gt-target " +
                            (dir / "pose.txt") + " --gt-source " + demo("demo-pcd2-gtpose.txt")),
                 "12 numbers");
}

TEST(Cli, NoReliableMatchExitsOneWithoutTransform) {
  REQUIRE_DEMO_ROOM();
  TempDir dir;
  // A map of scattered noise shares nothing with the room.
  std::ofstream out(dir / "noise.xyz");
  uint32_t s = 12345;
  for (int i = 0; i < 30000; ++i) {
    auto next = [&s] { return (s = s * 1664525u + 1013904223u) / 4294967296.0; };
    out << 6 * next() << " " << 6 * next() << " " << 3 * next() << "\n";
  }
  out.close();
  const auto r =
      runTomomap("match " + demo("demo-pcd1.pcd") + " " + (dir / "noise.xyz") + " --json " + (dir / "r.json"));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("no reliable match"), std::string::npos);
  EXPECT_EQ(r.output.find("T_target_source"), std::string::npos);
  std::ifstream in(dir / "r.json");
  const auto j = nlohmann::json::parse(in);
  EXPECT_FALSE(j["reliable"].get<bool>());
  EXPECT_FALSE(j.contains("T_target_source"));
}

TEST(Cli, SynthThenMatchOnAFreshMachine) {
  TempDir dir;
  const auto s = runTomomap("synth --world outdoor --seed 3 --out " + (dir / "w"));
  ASSERT_EQ(s.exit_code, 0) << s.output;
  const auto again = runTomomap("synth --world outdoor --seed 3 --out " + (dir / "w2"));
  ASSERT_EQ(again.exit_code, 0);
  std::ifstream a(dir / "w/map_1.pcd", std::ios::binary), b(dir / "w2/map_1.pcd", std::ios::binary);
  EXPECT_TRUE(std::equal(std::istreambuf_iterator<char>(a), {}, std::istreambuf_iterator<char>(b)))
      << "same seed must give the same map";
  const std::string w = dir / "w";
  const auto m = runTomomap("match " + w + "/map_0.pcd " + w + "/map_1.pcd --grid 0.2 --gt-target " + w +
                            "/map_0-gtpose.txt --gt-source " + w + "/map_1-gtpose.txt");
  EXPECT_EQ(m.exit_code, 0) << m.output;
  EXPECT_NE(m.output.find(": success"), std::string::npos) << m.output;
}

TEST(Cli, OneThreadOrTwoGiveTheSameAnswerSaidInTheSameOrder) {
  // With -j 2 both maps are described at once; what is said of each still
  // comes in order, and the answer is the one of -j 1, bit for bit.
  TempDir dir;
  ASSERT_EQ(runTomomap("synth --world room --seed 4 --out " + (dir / "w")).exit_code, 0);
  const std::string w = dir / "w";
  const std::string args = "match " + w + "/map_0.pcd " + w + "/map_1.pcd --grid 0.1";
  nlohmann::json answer[2];
  for (int threads : {1, 2}) {
    const std::string json = dir / ("j" + std::to_string(threads) + ".json");
    const auto r = runTomomap(args + " -j " + std::to_string(threads) + " --json " + json);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const size_t target = r.output.find("target " + w), source = r.output.find("source " + w);
    ASSERT_NE(target, std::string::npos) << r.output;
    EXPECT_LT(target, source) << r.output;
    std::ifstream in(json);
    answer[threads - 1] = nlohmann::json::parse(in);
  }
  EXPECT_EQ(answer[0]["T_target_source"], answer[1]["T_target_source"]);
  EXPECT_EQ(answer[0]["features"], answer[1]["features"]);
  EXPECT_EQ(answer[0]["lead_sigma"], answer[1]["lead_sigma"]);
  EXPECT_EQ(answer[0]["target_points"], answer[1]["target_points"]);

  // Both maps bad: the target is named, as when they are read in turn.
  std::ofstream(dir / "empty.pcd").flush();
  for (int threads : {1, 2}) {
    const auto r = runTomomap("match " + (dir / "empty.pcd") + " /nonexistent/b.pcd -j " + std::to_string(threads));
    expectBadInput(r, "empty.pcd");
    EXPECT_EQ(r.output.find("/nonexistent/b.pcd"), std::string::npos) << r.output;
  }
}

TEST(Cli, SynthRejectsBadOptions) {
  TempDir dir;
  expectBadInput(runTomomap("synth --world forest --out " + (dir / "x")), "--world");
  expectBadInput(runTomomap("synth --noise extreme --out " + (dir / "x")), "--noise");
  expectBadInput(runTomomap("synth --maps 0 --out " + (dir / "x")), "--maps");
  EXPECT_EQ(runTomomap("synth").exit_code, 2);  // --out is required
}

TEST(Cli, FpfhRansacBaselineRunsOnTheSamePair) {
  REQUIRE_DEMO_ROOM();
  TempDir dir;
  // At 0.1 m: at the demo's own 0.05 m the baseline took 43 s of CI's time, here 14 s (0.05 m off).
  const auto r =
      test::runBinary(TOMOMAP_BASELINE_BIN, demoMatchArgs().substr(6) + " --grid 0.1 -j 2 --json " + (dir / "b.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("normals + FPFH"), std::string::npos);
  std::ifstream in(dir / "b.json");
  const auto j = nlohmann::json::parse(in);
  EXPECT_EQ(j["method"], "fpfh-ransac");
  EXPECT_TRUE(j["error"]["success"].get<bool>()) << j.dump();
  EXPECT_EQ(test::runBinary(TOMOMAP_BASELINE_BIN, "a.pcd b.pcd --grid 0").exit_code, 2);
  EXPECT_EQ(test::runBinary(TOMOMAP_BASELINE_BIN, "/nonexistent.pcd b.pcd").exit_code, 2);
}

// The paper's method as published has no decision: on a small room it answers
// a copy of the room metres off, where tomomap answers right (the matrix in
// docs/results.md counts both over every family).
TEST(Cli, PaperConsensusBaselineAnswersWithoutADecision) {
  TempDir dir;
  const std::string w = dir / "room";
  ASSERT_EQ(runTomomap("synth --world room --seed 1 --noise low --out " + w).exit_code, 0);
  const std::string pair = w + "/map_0.pcd " + w + "/map_1.pcd --grid 0.1 --gt-target " + w +
                           "/map_0-gtpose.txt --gt-source " + w + "/map_1-gtpose.txt";
  const auto paper =
      test::runBinary(TOMOMAP_BASELINE_BIN, "--method paper-consensus " + pair + " --json " + (dir / "p.json"));
  ASSERT_EQ(paper.exit_code, 0) << "it answers whenever a slice pair gave an estimate\n" << paper.output;
  const auto j = nlohmann::json::parse(std::ifstream(dir / "p.json"));
  EXPECT_EQ(j["method"], "paper-consensus");
  EXPECT_FALSE(j["error"]["success"].get<bool>()) << j.dump();
  EXPECT_GT(j["error"]["translation"].get<double>(), 1.0) << j.dump();
  const auto ours = runTomomap("match " + pair);
  EXPECT_EQ(ours.exit_code, 0) << ours.output;
  EXPECT_NE(ours.output.find(": success"), std::string::npos) << ours.output;
  expectBadInput(test::runBinary(TOMOMAP_BASELINE_BIN, "--method icp " + pair), "--method");
}

// --candidates lists what the decision could have answered: on a small room
// the features' answer and every dense search's best poses, each refined and
// scored on the occupancy, and with ground truth which of them are right.
TEST(Cli, CandidatesListEveryProposedPoseScoredWithItsError) {
  TempDir dir;
  const std::string w = dir / "room";
  ASSERT_EQ(runTomomap("synth --world room --seed 1 --noise low --out " + w).exit_code, 0);
  const auto r =
      runTomomap("match " + w + "/map_0.pcd " + w + "/map_1.pcd --grid 0.1 --gt-target " + w +
                 "/map_0-gtpose.txt --gt-source " + w + "/map_1-gtpose.txt --candidates --json " + (dir / "c.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("candidates       "), std::string::npos) << r.output;
  const auto j = nlohmann::json::parse(std::ifstream(dir / "c.json"));
  ASSERT_TRUE(j.contains("candidates")) << j.dump();
  std::set<std::string> from;
  double best_score = -1e18;
  bool best_right = false;
  for (const auto& c : j["candidates"]) {
    from.insert(c["from"].get<std::string>());
    EXPECT_GE(c["refined"]["score"].get<double>(), c["proposed"]["score"].get<double>())
        << "on this room refining (a climb, the occupancy's height) only gains";
    if (c["refined"]["score"].get<double>() > best_score) {
      best_score = c["refined"]["score"].get<double>();
      best_right = c["error"]["success"].get<bool>();
    }
  }
  for (const char* search : {"features", "search_at_grid", "search_wide", "search_pooled"})
    EXPECT_TRUE(from.count(search)) << search << " proposed nothing\n" << r.output;
  EXPECT_TRUE(best_right) << "on this room the best-scoring candidate is the right pose\n" << r.output;
  // The decision answers a right candidate here, clear beyond chance, and says so.
  const auto& trial = j["candidate_decision"];
  ASSERT_FALSE(trial["answer"].is_null()) << trial.dump();
  EXPECT_TRUE(j["candidates"].at(trial["answer"].get<size_t>())["error"]["success"].get<bool>()) << trial.dump();
  EXPECT_GE(trial["lead_sigma"].get<double>(), 3.0);
  EXPECT_NE(r.output.find("decision         candidate "), std::string::npos) << r.output;
  // Its answer is finished in 6-DoF, and judged so: a level room's right
  // answer stays right and within a cell of the truth.
  EXPECT_TRUE(j["error"]["success"].get<bool>()) << j.dump();
  EXPECT_LT(j["error"]["translation"].get<double>(), 0.1) << j.dump();
  const auto plain = runTomomap("match " + w + "/map_0.pcd " + w + "/map_1.pcd --grid 0.1 --json " + (dir / "p.json"));
  EXPECT_EQ(plain.output.find("candidates       "), std::string::npos) << "listed only when asked\n" << plain.output;
  EXPECT_FALSE(nlohmann::json::parse(std::ifstream(dir / "p.json")).contains("candidates")) << "only when asked";
}

// The one decision over the candidates answers, and the pose it returns is
// the candidate it judged.
TEST(Cli, TheDecisionOverTheCandidatesAnswersWithThePoseItJudged) {
  TempDir dir;
  const std::string w = dir / "room";
  ASSERT_EQ(runTomomap("synth --world room --seed 1 --noise low --out " + w).exit_code, 0);
  const std::string pair = "match " + w + "/map_0.pcd " + w + "/map_1.pcd --grid 0.1 --gt-target " + w +
                           "/map_0-gtpose.txt --gt-source " + w + "/map_1-gtpose.txt";
  for (const bool finish : {false, true}) {
    const std::string json = dir / (finish ? "finished.json" : "judged.json");
    const auto r = runTomomap(pair + " --candidates" + (finish ? "" : " --no-finish") + " --json " + json);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("decision         candidate "), std::string::npos) << r.output;
    const auto j = nlohmann::json::parse(std::ifstream(json));
    ASSERT_TRUE(j["reliable"].get<bool>()) << j.dump();
    const auto& decision = j["candidate_decision"];
    ASSERT_FALSE(decision["answer"].is_null()) << decision.dump();
    const auto& judged = j["candidates"].at(decision["answer"].get<size_t>());
    EXPECT_EQ(j["answered_by"], judged["from"]);
    EXPECT_DOUBLE_EQ(j["lead_sigma"].get<double>(), decision["lead_sigma"].get<double>());
    EXPECT_EQ(j["height_offset_slices"], judged["refined"]["height_offset_slices"]);
    EXPECT_TRUE(j["error"]["success"].get<bool>()) << j.dump();
    if (!finish) {
      // Unfinished, the answer is the judged candidate's pose, to rounding.
      EXPECT_NEAR(j["error"]["translation"].get<double>(), judged["error"]["translation"].get<double>(), 1e-9);
      EXPECT_NEAR(j["error"]["yaw"].get<double>(), judged["error"]["yaw"].get<double>(), 1e-9);
    } else {
      // Finished, it is that pose finished in 6-DoF: the finish held and
      // moved it less than a cell.
      ASSERT_TRUE(j["finish"]["held"].get<bool>()) << j["finish"].dump();
      EXPECT_LT(j["finish"]["moved_m"].get<double>(), 0.1) << j["finish"].dump();
      EXPECT_NEAR(j["error"]["translation"].get<double>(), judged["error"]["translation"].get<double>(), 0.1);
    }
  }
}

namespace {

/// Pixels of exactly this BGR colour.
int countColour(const cv::Mat& img, const cv::Vec3b& c) {
  int n = 0;
  for (int v = 0; v < img.rows; ++v)
    for (int u = 0; u < img.cols; ++u) n += img.at<cv::Vec3b>(v, u) == c;
  return n;
}

}  // namespace

TEST(Cli, VizDrawsAnAlignedOverlayAndTheWinningSlicePairs) {
  REQUIRE_DEMO_ROOM();
  TempDir dir;
  std::string args = demoMatchArgs();
  args.replace(0, 5, "viz");
  const auto r = runTomomap(args + " -o " + (dir / "pics") + " --pairs 2");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("overlay.png"), std::string::npos) << r.output;
  const cv::Mat overlay = cv::imread(dir / "pics/overlay.png");
  const cv::Mat pairs = cv::imread(dir / "pics/slice-pairs.png");
  ASSERT_FALSE(overlay.empty());
  ASSERT_FALSE(pairs.empty());
  EXPECT_GE(overlay.cols, 800);
  // Aligned maps mostly coincide: the "both" colour outweighs target-only cells.
  const int both = countColour(overlay, {60, 40, 40}), target_only = countColour(overlay, {178, 114, 0});
  EXPECT_GT(both, target_only) << "both " << both << ", target only " << target_only;
  // Two slice pairs, each with green inlier lines.
  EXPECT_GT(pairs.rows, 2 * 100);
  EXPECT_GT(countColour(pairs, {40, 170, 40}), 100);

  // An unwritable output folder is bad input, reported as such.
  const auto bad = runTomomap(args + " -o /proc/nope");
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
}

TEST(Cli, StatusWithoutADaemonsStateSaysSo) {
  TempDir dir;
  expectBadInput(runTomomap("status " + (dir / "nothing")), "status.json: cannot read");
  std::ofstream(dir / "status.json") << "{\"agent\": \"alpha\", \"map\": ";  // cut off
  expectBadInput(runTomomap("status " + dir.path.string()), "not valid JSON");
  std::ofstream(dir / "status.json") << "{\"agent\": \"alpha\"}";
  expectBadInput(runTomomap("status " + dir.path.string()), "not a tomomapd status file");
}

TEST(Cli, FleetKeysMakesAFleetAndRefusesBadRequests) {
  TempDir dir;
  const auto made = runTomomap("fleet-keys --agents alpha,bravo -o " + (dir / "fleet"));
  ASSERT_EQ(made.exit_code, 0) << made.output;
  EXPECT_NE(made.output.find("keep ca.key on this machine only"), std::string::npos) << made.output;
  EXPECT_NE(made.output.find("[security]"), std::string::npos) << "prints the config table to add";
  for (const std::string f : {"ca.pem", "ca.key", "alpha/key.pem", "alpha/cert.pem", "bravo/permissions.p7s"})
    EXPECT_TRUE(std::filesystem::exists(dir / ("fleet/" + f))) << f;
  expectBadInput(runTomomap("fleet-keys --agents alpha -o " + (dir / "fleet")), "--replace");
  expectBadInput(runTomomap("fleet-keys --agents 'bad id' -o " + (dir / "fleet")), "agent id 'bad id'");
  expectBadInput(runTomomap("fleet-keys -o " + (dir / "fleet")), "nothing to do");
  expectBadInput(runTomomap("fleet-keys --revoke zulu -o " + (dir / "fleet")), "cannot revoke zulu");
  const auto revoked = runTomomap("fleet-keys --revoke bravo -o " + (dir / "fleet"));
  EXPECT_EQ(revoked.exit_code, 0) << revoked.output;
  EXPECT_TRUE(std::filesystem::exists(dir / "fleet/crl.pem"));
}

TEST(Cli, ATiltedSynthMapIsLevelledAndRefusedWithNoLevel) {
  // A 10 degree roll once came out as a reliable answer 0.6 m off.
  TempDir dir;
  const auto gen = runTomomap("synth -o " + (dir / "w") + " -s 3 --scale 0.5 --tilt 10");
  ASSERT_EQ(gen.exit_code, 0) << gen.output;
  const std::string maps = (dir / "w/map_0.pcd") + " " + (dir / "w/map_1.pcd");
  const std::string gt =
      " --gt-target " + (dir / "w/map_0-gtpose.txt") + " --gt-source " + (dir / "w/map_1-gtpose.txt");

  const auto levelled = runTomomap("match --json " + (dir / "levelled.json") + " " + maps + gt);
  ASSERT_EQ(levelled.exit_code, 0) << levelled.output;
  // The tilt's uncertainty is the spread over the map's parts: under a degree on a synthetic floor.
  EXPECT_TRUE(std::regex_search(
      levelled.output, std::regex(R"(levelled: it leaned 10\.0 \+- 0\.\d deg from gravity \(read off its floors\))")))
      << levelled.output;
  const auto l = nlohmann::json::parse(std::ifstream(dir / "levelled.json"));
  EXPECT_TRUE(l["error"]["success"].get<bool>()) << l.dump(2);
  EXPECT_LT(l["error"]["translation"].get<double>(), 0.15);
  EXPECT_LT(l["error"]["yaw"].get<double>(), radians(1.0)) << "the whole rotation, roll included";
  EXPECT_TRUE(l.contains("T_target_source_6dof"));
  EXPECT_LT(l["tilt_deg"]["target"].get<double>(), 0.5);
  EXPECT_NEAR(l["tilt_deg"]["source"].get<double>(), 10.0, 0.3);

  const auto refused = runTomomap("match --no-level --json " + (dir / "refused.json") + " " + maps);
  EXPECT_EQ(refused.exit_code, 1) << refused.output;
  EXPECT_TRUE(std::regex_search(
      refused.output, std::regex(R"(no reliable match: source map is tilted 10\.0 \+- 0\.\d deg from gravity)")))
      << refused.output;
  EXPECT_NE(refused.output.find("levelling is off"), std::string::npos) << refused.output;
  EXPECT_FALSE(nlohmann::json::parse(std::ifstream(dir / "refused.json"))["reliable"].get<bool>());
}

TEST(Cli, VizDrawsAsManySlicePairsAsAskedAndWritesJson) {
  // --pairs 3 once drew one pair (three image rows were counted per pair).
  REQUIRE_DEMO_ROOM();
  TempDir dir;
  std::string args = demoMatchArgs();
  args.replace(0, 5, "viz");
  ASSERT_EQ(runTomomap(args + " -o " + (dir / "one") + " --pairs 1").exit_code, 0);
  const auto three = runTomomap(args + " -o " + (dir / "three") + " --pairs 3 --json " + (dir / "viz.json"));
  ASSERT_EQ(three.exit_code, 0) << three.output;
  const cv::Mat a = cv::imread(dir / "one/slice-pairs.png"), b = cv::imread(dir / "three/slice-pairs.png");
  ASSERT_FALSE(a.empty());
  ASSERT_FALSE(b.empty());
  EXPECT_GT(b.rows, 2.5 * a.rows) << "three pairs stacked, not one";
  EXPECT_TRUE(nlohmann::json::parse(std::ifstream(dir / "viz.json"))["reliable"].get<bool>());
}

TEST(Cli, QuietIsOneLineJsonGoesToStdoutAndTyposGetASuggestion) {
  REQUIRE_DEMO_ROOM();
  const auto quiet = runTomomap(demoMatchArgs() + " -q");
  ASSERT_EQ(quiet.exit_code, 0) << quiet.output;
  EXPECT_EQ(lines(quiet.output), 1u) << quiet.output;
  EXPECT_EQ(quiet.output.rfind("T_target_source  x ", 0), 0u) << quiet.output;

  // The text goes to stderr, stdout is one JSON document.
  const auto piped = runTomomap(demoMatchArgs() + " -q --json -");
  ASSERT_EQ(piped.exit_code, 0) << piped.output;
  const auto j = nlohmann::json::parse(piped.output.substr(piped.output.find('{')));
  EXPECT_TRUE(j["reliable"].get<bool>());
  EXPECT_FALSE(std::filesystem::exists("-")) << "no file named '-'";

  const auto typo = runTomomap("mtach a.pcd b.pcd");
  EXPECT_EQ(typo.exit_code, 2);
  EXPECT_NE(typo.output.find("unknown command 'mtach'; did you mean 'match'?"), std::string::npos) << typo.output;

  const auto zero = runTomomap(demoMatchArgs() + " --grid 0");
  EXPECT_EQ(zero.exit_code, 2);
  EXPECT_NE(zero.output.find("grid size must be a number of metres from 0.005 to 10"), std::string::npos)
      << zero.output;
  EXPECT_LT(zero.output.size(), 300u) << zero.output;
}

TEST(Cli, AMapInMillimetresGetsAHintAndStatusJsonAlwaysPrintsADocument) {
  REQUIRE_DEMO_ROOM();
  TempDir dir;
  Points mm = loadMap(demo("demo-pcd2.pcd"));
  for (auto& p : mm) p *= 1000.0f;
  savePcd(dir / "mm.pcd", mm);
  const auto r = runTomomap("match " + demo("demo-pcd1.pcd") + " " + (dir / "mm.pcd"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("likely in millimetres"), std::string::npos) << r.output;

  const auto none = runTomomap("status --json " + (dir / "no-state"));
  EXPECT_EQ(none.exit_code, 2);
  const size_t open = none.output.find('{'), close = none.output.rfind('}');
  ASSERT_NE(open, std::string::npos) << none.output;
  const auto j = nlohmann::json::parse(none.output.substr(open, close - open + 1));
  EXPECT_FALSE(j["running"].get<bool>());
  EXPECT_NE(j["error"].get<std::string>().find("cannot read"), std::string::npos);
}

// docs/json.md is the contract for programs that read tomomap's JSON: every
// field it lists is written, and nothing is written that it does not list.
TEST(Cli, TheJsonOutputIsTheDocumentedContract) {
  TempDir dir;
  ASSERT_EQ(runTomomap("synth -o " + (dir / "building") + " -n 2 -s 1 --scale 0.5").exit_code, 0);
  ASSERT_EQ(runTomomap("synth -o " + (dir / "street") + " -w outdoor -n 1 -s 1 --scale 0.5").exit_code, 0);
  const std::string b = dir / "building/";
  const auto right =
      runTomomap("match --json " + (dir / "right.json") + " --grid 0.1 --gt-target " + b +
                 "map_0-gtpose.txt --gt-source " + b + "map_1-gtpose.txt " + b + "map_0.pcd " + b + "map_1.pcd");
  ASSERT_EQ(right.exit_code, 0) << right.output;
  const auto none = runTomomap("match --json " + (dir / "none.json") + " --grid 0.1 " + b + "map_0.pcd " +
                               (dir / "street/map_0.pcd"));
  ASSERT_EQ(none.exit_code, 1) << none.output;
  const auto a = nlohmann::json::parse(readText(dir / "right.json"));
  const auto n = nlohmann::json::parse(readText(dir / "none.json"));
  EXPECT_EQ(a["schema_version"], kJsonSchemaVersion);
  EXPECT_EQ(a["grid"], 0.1);
  EXPECT_EQ(a["target"], b + "map_0.pcd");
  EXPECT_EQ(a["tool"]["name"], "tomomap");
  EXPECT_FALSE(a["tool"]["version"].get<std::string>().empty());

  std::set<std::string> written = keysOf(a);
  for (const auto& k : keysOf(n)) written.insert(k);
  std::set<std::string> documented = documentedJsonFields("`match --json`");
  ASSERT_FALSE(documented.empty());
  for (const auto& k : written) EXPECT_TRUE(documented.count(k)) << k << " is written but not in docs/json.md";
  documented.erase("T_target_source_6dof");  // only with --level
  documented.erase("candidates");            // only with --candidates
  documented.erase("candidate_decision");    // only where the maps were not refused before any search
  for (const auto& k : documented) EXPECT_TRUE(written.count(k)) << k << " is in docs/json.md but not written";
}
