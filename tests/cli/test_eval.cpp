// `tomomap eval` as a user runs it: suites, errors with line numbers, rows, summary.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <regex>
#include <sstream>

#include "support.hpp"

using namespace tomomap;
using tomomap::test::documentedJsonFields;
using tomomap::test::keysOf;
using tomomap::test::runTomomap;
using tomomap::test::TempDir;

/// Writes `suite` as DIR/s.toml and runs `tomomap eval` on it into DIR/out, with `options`.
static test::CommandResult evalSuite(const TempDir& dir, const std::string& suite, const std::string& options = "") {
  std::ofstream(dir / "s.toml") << suite;
  return runTomomap("eval " + (dir / "s.toml") + (options.empty() ? "" : " " + options) + " -o " + (dir / "out"));
}

/// DIR/out/rows.jsonl, a row each.
static std::vector<nlohmann::json> jsonRows(const TempDir& dir) {
  std::ifstream jsonl(dir / "out/rows.jsonl");
  std::vector<nlohmann::json> rows;
  for (std::string line; std::getline(jsonl, line);) rows.push_back(nlohmann::json::parse(line));
  return rows;
}

static std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(Eval, SuiteErrorsNameFileLineAndProblem) {
  TempDir dir;
  // The suite `text` (evalSuite's s.toml) is refused (exit code 2), its error saying each of `says`.
  const auto refused = [&](const std::string& what, const std::string& text, const std::vector<std::string>& says) {
    SCOPED_TRACE(what);
    const auto r = evalSuite(dir, text);
    EXPECT_EQ(r.exit_code, 2);
    for (const std::string& s : says) EXPECT_NE(r.output.find(s), std::string::npos) << s << "\n" << r.output;
  };
  refused("syntax", "name = \"x\"\n[[pair]\ntarget = 1\n", {"s.toml:2:"});
  refused("method", "name = \"x\"\nmethods = [\"tomomap\", \"icp\"]\n[[synth]]\nworld = \"indoor\"\n",
          {"s.toml:2:", "unknown method 'icp'"});
  refused("key", "[[synth]]\nworld = \"indoor\"\nseed = [1]\n", {"s.toml:3:", "unknown key 'seed'"});
  // A sequence turned is levelled first: asking for both, or a turn past 90 deg, is said where.
  refused("turn with level", "[[sequence]]\nfolder = \"seq\"\nlevel = true\nturn = 40\n",
          {"s.toml:4:", "'turn' levels each map first"});
  refused("turn past 90", "[[sequence]]\nfolder = \"seq\"\nturn = 120\n", {"'turn' must be 0 to 90 degrees"});
}

TEST(Eval, MissingMapIsLeftOutAndTheRestRuns) {
  REQUIRE_DEMO_ROOM();
  TempDir dir;
  const std::string d = test::demoRoom() + "/";
  const std::string truth =
      "gt_target = \"" + d + "demo-pcd1-gtpose.txt\"\ngt_source = \"" + d + "demo-pcd2-gtpose.txt\"\n";
  const auto r = evalSuite(dir,
                           "name = \"mixed\"\nmethods = [\"tomomap\"]\n[[pair]]\nname = \"gone\"\n"
                           "target = \"/nonexistent/a.pcd\"\nsource = \"" +
                               d + "demo-pcd2.pcd\"\n" + truth + "[[pair]]\nname = \"room\"\ntarget = \"" + d +
                               "demo-pcd1.pcd\"\nsource = \"" + d + "demo-pcd2.pcd\"\n" + truth + "grid = 0.05\n");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("pair 'gone' left out"), std::string::npos) << r.output;
  const std::string rows = slurp(dir / "out/rows.csv");
  EXPECT_NE(rows.find("\"room\",real,\"pairs\",tomomap,0,1,1"), std::string::npos) << rows;
  const std::string md = slurp(dir / "out/summary.md");
  EXPECT_NE(md.find("| tomomap | real | 1 | 1/1 |"), std::string::npos) << md;
}

// Pairs cut from a scan (here a generated room's map; the real scans beside
// the repository are used the same way), the source moved within `move`, and
// the table a regression matrix reads: right, refused and wrong per family.
TEST(Eval, AScanBlockCutsPairsWithGroundTruthAndCountsRightRefusedWrong) {
  TempDir dir;
  const auto gen = runTomomap("synth -w room -s 2 --noise low -o " + (dir / "room"));
  ASSERT_EQ(gen.exit_code, 0) << gen.output;
  const auto r = evalSuite(dir,
                           "name = \"scans\"\nmethods = [\"tomomap\"]\n[[scan]]\nfile = \"room/map_0.pcd\"\n"
                           "name = \"room-scan\"\nseeds = [1, 2]\ngrid = 0.1\nmove = 3\n[[scan]]\n"
                           "file = \"nowhere/scan.pcd\"\n");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("scan 'scan' left out: "), std::string::npos) << r.output;
  const auto pair = nlohmann::json::parse(slurp(dir / "out/worlds/room-scan-1-g0.1/pair.json"));
  EXPECT_GE(pair["overlap"].get<double>(), 0.2) << pair.dump(2);
  EXPECT_LE(pair["overlap"].get<double>(), 0.6) << pair.dump(2);
  EXPECT_GE(pair["thinning"].get<int>(), 3) << "odd seeds thin one crop";
  // The source moved no further than the block's `move` (default 20 m).
  for (const char* axis : {"x", "y"}) {
    const double d = pair["move"][axis].get<double>();
    EXPECT_LE(std::abs(d), 3.0) << pair.dump(2);
  }
  // Every run lands in exactly one of right, refused, wrong or errors.
  const std::string md = slurp(dir / "out/summary.md");
  const std::regex row(R"(\| tomomap \| room-scan g0.1 \| 2 \| ([0-9]) \| ([0-9]) \| ([0-9]) \| ([0-9]) \|)");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(md, m, row)) << md;
  EXPECT_EQ(std::stoi(m[1]) + std::stoi(m[2]) + std::stoi(m[3]) + std::stoi(m[4]), 2) << md;
  EXPECT_EQ(std::stoi(m[4]), 0) << "no run failed to run\n" << md;
}

// A seed whose cut leaves a crop too small to be a map is no pair: the run
// says so, lists it in the summary, and goes on with the other seeds (kitti's
// seed 179 once ended a run of 396 pairs). A scan of 3,000 points: every odd
// seed thins a crop of at most 71 % of it by 3 or more, under 1,000 points;
// even seeds add noise instead and keep over 1,600.
TEST(Eval, ASeedThatCutsTooSmallACropIsSkippedAndSaidAndTheRestRuns) {
  TempDir dir;
  {
    std::ofstream xyz(dir / "small.xyz");
    for (int i = 0; i < 3000; ++i) {  // the walls of a 4 x 3 m room, 2 m high
      const double along = 14.0 * i / 3000, z = 2.0 * ((i * 7) % 3000) / 3000;
      const double x = along < 4 ? along : along < 7 ? 4 : along < 11 ? 11 - along : 0;
      const double y = along < 4 ? 0 : along < 7 ? along - 4 : along < 11 ? 3 : 14 - along;
      xyz << x << " " << y << " " << z << "\n";
    }
  }
  const auto r = evalSuite(dir,
                           "name = \"small\"\nmethods = [\"tomomap\"]\n[[scan]]\nfile = \"small.xyz\"\n"
                           "name = \"small\"\nseeds = [1, 2]\ngrid = 0.1\n");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("warning: skipping small-1-g0.1: cutting this scan left a crop of "), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("[1/1] small-2-g0.1-"), std::string::npos) << "seed 2 still runs\n" << r.output;
  const std::string md = slurp(dir / "out/summary.md");
  EXPECT_NE(md.find("| tomomap | small g0.1 | 1 |"), std::string::npos) << md;
  EXPECT_NE(md.find("Skipped (no pair to match, not counted above):\n- small-1-g0.1: cutting this scan left"),
            std::string::npos)
      << md;
}

// `-j 1` is one thread for every stage of a match (slicing, features and the
// dense refinement once took every core whatever it said): each run's
// processor time stays within its wall time. On a busy machine a run on two
// threads could pass too; on an idle one it spent 1.4x its wall time.
TEST(Eval, OneThreadAskedKeepsEachRunOnOneCore) {
  TempDir dir;
  const auto r = evalSuite(dir,
                           "name = \"one\"\nmethods = [\"tomomap\"]\n[[synth]]\nworld = \"room\"\nseeds = [1, 2]\n"
                           "noise = [\"low\"]\ngrid = 0.05\n",
                           "-j 1");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto rows = jsonRows(dir);
  EXPECT_EQ(rows.size(), 2u);
  for (const auto& row : rows) {
    EXPECT_GT(row["cpu_s"].get<double>(), 0.0) << row.dump();
    EXPECT_LE(row["cpu_s"].get<double>(), row["wall_s"].get<double>()) << row.dump();
  }
}

// A build copied under another name to be compared with the installed one
// evaluates itself: its matches are its own, not those of a `tomomap`
// that happens to lie beside it (here there is none: every run would fail).
TEST(Eval, ACopyUnderAnotherNameRunsItsOwnMatches) {
  TempDir dir;
  const std::string copy = dir / "tomomap-trial";
  std::filesystem::copy_file(TOMOMAP_BIN, copy);
  std::filesystem::permissions(copy, std::filesystem::perms::owner_exec, std::filesystem::perm_options::add);
  std::ofstream(dir / "s.toml") << "name = \"trial\"\nmethods = [\"tomomap\"]\n[[synth]]\nworld = \"room\"\n"
                                   "seeds = [1]\nnoise = [\"low\"]\ngrid = 0.1\n";
  const auto r = test::runBinary(copy, "eval " + (dir / "s.toml") + " -o " + (dir / "out"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto rows = jsonRows(dir);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_TRUE(rows[0]["exit_code"] == 0 || rows[0]["exit_code"] == 1) << rows[0].dump();
}

// The CI suite shipped with the project: both world types, three noise levels,
// tomomap on every pair, the FPFH-RANSAC baseline beside it where the noise is
// high. Asserts tomomap's success rate; timings are reported, never asserted.
TEST(Eval, CiSuiteSucceedsAndDrawsBoxPlots) {
  TempDir dir;
  const auto r = runTomomap("eval " + std::string(TOMOMAP_SOURCE_DIR) + "/tests/suites/ci.toml -o " + (dir / "out"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::cout << r.output;
  for (const char* noise : {"none", "low", "high"})
    EXPECT_NE(r.output.find(std::string("| tomomap | ") + noise + " | 2 | 2/2 |"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("| fpfh-ransac | high | 1 |"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("| fpfh-ransac | low |"), std::string::npos) << "the baseline runs where the suite says";
  EXPECT_NE(r.output.find("fpfh-ransac / tomomap: median time"), std::string::npos) << r.output;
  const std::string rows = slurp(dir / "out/rows.csv");
  EXPECT_EQ(std::count(rows.begin(), rows.end(), '\n'), 1 + 6 + 1) << rows;
  std::ifstream jsonl(dir / "out/rows.jsonl");
  std::string first;
  ASSERT_TRUE(std::getline(jsonl, first));
  EXPECT_EQ(keysOf(nlohmann::json::parse(first)), documentedJsonFields("`rows.jsonl`"))
      << "rows.jsonl as docs/json.md lists it";
  const cv::Mat plots = cv::imread(dir / "out/boxplots.png");
  ASSERT_FALSE(plots.empty());
  EXPECT_GT(plots.cols, 1000);
}

TEST(Eval, ASynthBlockMayNameOnlyTheSuitesMethods) {
  TempDir dir;
  const auto r = evalSuite(
      dir, "name = \"x\"\nmethods = [\"tomomap\"]\n[[synth]]\nworld = \"indoor\"\nmethods = [\"fpfh-ransac\"]\n");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("s.toml:5:"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("not one of the suite's methods"), std::string::npos) << r.output;
}

TEST(Eval, ARunPastTheTimeoutIsKilledAndSaysSoAndTheSuiteGoesOn) {
  TempDir dir;
  // The baseline takes tens of seconds on this world; half a second is never enough.
  const auto r = evalSuite(dir,
                           "name = \"t\"\nmethods = [\"fpfh-ransac\", \"tomomap\"]\n[[synth]]\nworld = \"indoor\"\n"
                           "seeds = [1]\nnoise = [\"low\"]\nscale = 0.5\ngrid = 0.1\n",
                           "--timeout 0.5");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("[1/2] indoor-low-1-x0.5-g0.1 fpfh-ransac: running"), std::string::npos)
      << "said before it starts\n"
      << r.output;
  const auto rows = jsonRows(dir);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0]["method"], "fpfh-ransac");
  EXPECT_EQ(rows[0]["exit_code"], -1);
  EXPECT_EQ(rows[0]["note"], "timed out after 0.5 s");
  EXPECT_FALSE(rows[0]["success"].get<bool>());
  EXPECT_EQ(rows[1]["method"], "tomomap") << "the next run still ran";
}

// A user's own SLAM output, as the SLAM saved it: a folder of keyframe scans
// in the sensor's frame and a KITTI pose file, the sensor leaning 5 degrees.
// `tomomap eval --scans --poses` cuts two robots' maps from it, each leaning
// as its first keyframe did, and says how tomomap does on them.
TEST(Eval, APosedSequenceOfAUsersScansIsCutIntoPairsAndJudged) {
  TempDir dir;
  const auto gen = runTomomap("synth -w room -s 3 --noise none -o " + (dir / "room"));
  ASSERT_EQ(gen.exit_code, 0) << gen.output;
  const Points world = loadMap(dir / "room/map_0.pcd");
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(INFINITY), hi = -lo;
  for (const auto& p : world) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  std::filesystem::create_directories(dir / "scans");
  std::ofstream poses(dir / "optimized_poses.txt");
  const int keyframes = 24;
  for (int k = 0; k < keyframes; ++k) {
    // Along the room's length at mid height, leaning 5 degrees and turning as it goes.
    const float s = static_cast<float>(k) / (keyframes - 1);
    Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
    T.topLeftCorner<3, 3>() = (Eigen::AngleAxisd(0.3 * k, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(radians(5.0), Eigen::Vector3d::UnitX()))
                                  .toRotationMatrix();
    T.topRightCorner<3, 1>() = Eigen::Vector3f(lo.x() + (0.2f + 0.6f * s) * (hi.x() - lo.x()), 0.5f * (lo.y() + hi.y()),
                                               0.5f * (lo.z() + hi.z()))
                                   .cast<double>();
    const Eigen::Matrix4d body_world = T.inverse();
    Points scan;
    for (const auto& p : world)
      if ((p.cast<double>() - T.topRightCorner<3, 1>()).norm() < 3.0)
        scan.push_back((body_world * p.cast<double>().homogeneous()).head<3>().cast<float>());
    char name[32];
    std::snprintf(name, sizeof name, "%06d.pcd", k);
    savePcd((std::filesystem::path(dir / "scans") / name).string(), scan);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) poses << T(r, c) << (r == 2 && c == 3 ? "\n" : " ");
  }
  poses.close();
  const auto r = runTomomap("eval --scans " + (dir / "scans") + " --poses " + (dir / "optimized_poses.txt") +
                            " --grid 0.1 --pairs 2 --range 10 -o " + (dir / "out"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string md = slurp(dir / "out/summary.md");
  // The family is named after the scans' folder, with the grid and how the maps lie.
  const std::regex row(R"(\| tomomap \| [^|]* g0.1 leaning \| 2 \| ([0-9]) \| ([0-9]) \| ([0-9]) \| ([0-9]) \|)");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(md, m, row)) << md;
  EXPECT_EQ(std::stoi(m[4]), 0) << "no run failed to run\n" << md;
  EXPECT_EQ(std::stoi(m[3]), 0) << "no answer wrong\n" << md;
  size_t pairs = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir / "out/worlds")) {
    const auto pair = nlohmann::json::parse(slurp((e.path() / "pair.json").string()));
    ++pairs;
    EXPECT_NEAR(pair["lean_deg"]["target"].get<double>(), 5.0, 0.5) << pair.dump(2);
    EXPECT_NEAR(pair["lean_deg"]["source"].get<double>(), 5.0, 0.5) << pair.dump(2);
    EXPECT_GT(pair["overlap"]["target"].get<double>(), 0.0) << pair.dump(2);
  }
  EXPECT_EQ(pairs, 2u);
  // The same sequence from a suite, by a folder relative to the suite file
  // that holds scans/ and optimized_poses.txt, levelled.
  const auto suite = evalSuite(dir,
                               "name = \"mine\"\nmethods = [\"tomomap\"]\n[[sequence]]\nfolder = \".\"\n"
                               "seeds = [1]\ngrid = 0.1\nrange = 10\nlevel = true\n");
  ASSERT_EQ(suite.exit_code, 0) << suite.output;
  const auto rows = jsonRows(dir);
  ASSERT_EQ(rows.size(), 1u) << suite.output;
  EXPECT_NE(rows[0]["family"].get<std::string>().find(" g0.1 levelled"), std::string::npos) << rows[0].dump();
  EXPECT_NE(rows[0]["exit_code"].get<int>(), 2) << rows[0].dump();
  // A pose file that does not fit its scans is refused, saying both counts.
  std::ofstream(dir / "short.txt") << "1 0 0 0 0 1 0 0 0 0 1 0\n";
  const auto bad =
      runTomomap("eval --scans " + (dir / "scans") + " --poses " + (dir / "short.txt") + " -o " + (dir / "bad"));
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("24 scans (.pcd, .ply, .xyz), but"), std::string::npos) << bad.output;
  // A sequence's options beside a suite file are said, not ignored.
  const auto beside = runTomomap("eval " + (dir / "s.toml") + " --pairs 3 -o " + (dir / "beside"));
  EXPECT_EQ(beside.exit_code, 2) << beside.output;
  EXPECT_NE(beside.output.find("--pairs requires --scans"), std::string::npos) << beside.output;
}
