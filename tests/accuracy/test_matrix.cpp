// The regression matrix (tests/suites/matrix.toml) as a gate: no family of
// maps may answer wrong, nor fewer right than it did when its floor below was
// last raised. A change to the decision that breaks a family it was not made for fails
// here, not in a user's hands (docs/results.md has the whole table).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "support.hpp"

using namespace tomomap;

namespace {

struct FamilyTally {
  int right = 0, refused = 0, wrong = 0, errors = 0;
};

/// Right / refused / wrong / errors per family, from eval's rows.jsonl.
std::map<std::string, FamilyTally> tallies(const std::filesystem::path& rows) {
  std::ifstream in(rows);
  std::map<std::string, FamilyTally> out;
  for (std::string line; std::getline(in, line);) {
    const auto row = nlohmann::json::parse(line);
    if (row["method"] != "tomomap") continue;
    FamilyTally& t = out[row["family"].get<std::string>()];
    const int exit_code = row["exit_code"].get<int>();
    if (row["success"].get<bool>())
      ++t.right;
    else if (exit_code == 1)
      ++t.refused;
    else if (exit_code == 0)
      ++t.wrong;
    else
      ++t.errors;
  }
  return out;
}

}  // namespace

TEST(RegressionMatrix, NoFamilyAnswersWrongOrFewerRightThanItsFloor) {
  // Right answers per family at the last raise of the floors (the matrix's
  // run in docs/results.md). Real-data families are checked where the data is.
  // sunrgbd g0.05 5 -> 4 with its pairs' source moved within 4 m, not 20: the
  // same crops, the source's raster at another sub-cell phase (seed 31 refused).
  // kitti g0.2 3 -> 4: a thin feature answer confirmed over 2 slices (seed 16).
  // sunrgbd g0.05 4 -> 5: a clear winner on too few inliers checked wide (seed 31).
  // sunrgbd g0.05 5 -> 8, g0.1 1 -> 2: sparse slices described, answers moved uphill.
  // kitti g0.2 4 -> 5: an ambiguous winner checked wide (seed 16).
  // sunrgbd once wrong: 156, 200, 286 refused; 164 (climbed from the wide search's pose) and 275 (uphill) right.
  // The one decision over the candidates in the verdict's place (2026-12-01):
  // kitti g0.2 5 -> 8, sunrgbd g0.05 8 -> 9, g0.1 2 -> 3; two families one
  // fewer, each a pair the verdict answered on a rule set for it: outdoor
  // g0.5 x0.5 10 -> 9 (seed 3 high: 1.9 sigma on the occupancy, 2.5 on the
  // features' votes), sunrgbd once wrong 2 -> 1 (275: three slices, where no
  // lead over the slices reaches 3 sigma) (docs/results.md, "The decision answers").
  // The verdict deleted (2026-12-01): sunrgbd g0.05 9 -> 8, the verdict's
  // count: crop 34, its features' two answers tied at one slice pair each,
  // was answered where the verdict's re-choice of a weak feature winner on
  // the occupancy (chooseByLanding) refined the right one; as one rival among
  // the candidates it climbs off its one estimate, and nothing corroborates
  // it (docs/results.md, "The verdict deleted").
  // hku-main-building: maps leaning as SLAM saved them, every pair right with
  // the 6-DoF finish and the tilt's uncertainty read off the map's parts;
  // turned 40 deg (2026-12-02), 7 right where 0 were (levelled where their
  // lines stand), seed 2 refused: one map's halves read it 90 deg apart.
  // indoor g0.05 x0.5 and outdoor g0.2 x0.5 all right: SynthAccuracy counts
  // their seeds 1-5 as right and matches only 6-10 (test_synth_worlds.cpp).
  const std::map<std::string, int> floor = {{"demo-room g0.05", 2},
                                            {"indoor g0.05 x0.5", 10},
                                            {"indoor g0.1 x0.5", 10},
                                            {"indoor g0.1 x0.5 tilt1", 3},
                                            {"indoor g0.1 x0.5 tilt3", 3},
                                            {"indoor g0.1 x0.5 tilt10", 3},
                                            {"indoor g0.1 x0.5 tilt30", 2},
                                            {"indoor g0.2", 5},
                                            {"indoor g0.2 x0.5", 10},
                                            {"outdoor g0.1 x0.5", 9},
                                            {"outdoor g0.2 x0.5", 10},
                                            {"outdoor g0.5 x0.5", 9},
                                            {"room g0.05", 20},
                                            {"room g0.1", 20},
                                            {"sunrgbd-room g0.05", 8},
                                            {"sunrgbd-room g0.1", 3},
                                            {"sunrgbd-room-once-wrong g0.05", 1},
                                            {"nuscenes-lidar g0.2", 0},
                                            {"kitti-lidar g0.2", 8},
                                            {"hku-main-building g0.1 leaning", 8},
                                            {"hku-main-building g0.1 levelled", 8},
                                            {"hku-main-building g0.2 leaning", 8},
                                            {"hku-main-building g0.2 levelled", 8},
                                            {"hku-main-building g0.1 turned 40", 7}};
  test::TempDir dir;
  // tomomap alone: the paper's method, which the suite runs beside it for
  // docs/results.md, answers wrong by design (it has no decision).
  const auto run = test::runTomomap("eval " + std::string(TOMOMAP_SOURCE_DIR) +
                                    "/tests/suites/matrix.toml -m tomomap --candidates --out " + (dir / "matrix"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const std::map<std::string, FamilyTally> got = tallies(dir.path / "matrix/rows.jsonl");
  // Real data is read from ../shared beside the checkout; every other family is generated and runs anywhere.
  const std::set<std::string> real_data = {"demo-room g0.05",
                                           "sunrgbd-room g0.05",
                                           "sunrgbd-room g0.1",
                                           "nuscenes-lidar g0.2",
                                           "kitti-lidar g0.2",
                                           "sunrgbd-room-once-wrong g0.05",
                                           "hku-main-building g0.1 leaning",
                                           "hku-main-building g0.1 levelled",
                                           "hku-main-building g0.2 leaning",
                                           "hku-main-building g0.2 levelled",
                                           "hku-main-building g0.1 turned 40"};
  for (const auto& entry : floor) {
    if (!real_data.count(entry.first)) {
      EXPECT_TRUE(got.count(entry.first)) << entry.first << " did not run\n" << run.output;
    }
  }
  for (const auto& [family, t] : got) {
    SCOPED_TRACE(family);
    ASSERT_TRUE(floor.count(family)) << "a family with no floor: add it above";
    EXPECT_EQ(t.wrong, 0);
    EXPECT_EQ(t.errors, 0);
    EXPECT_GE(t.right, floor.at(family)) << t.right << " right, " << t.refused << " refused";
  }
  if (test::haveDemoRoom()) {
    EXPECT_EQ(got.size(), floor.size()) << "the real-data families ran too";
  }
  // Maps cut from a SLAM sequence with at least 30 % overlap: every one right,
  // and a leaning pair's answer within 2 grid cells over the source's points
  // and 0.5 degrees of rotation (what the 6-DoF finish is for).
  std::ifstream rows(dir.path / "matrix/rows.jsonl");
  for (std::string line; std::getline(rows, line);) {
    const auto row = nlohmann::json::parse(line);
    const std::string family = row["family"], pair = row["pair"];
    const bool leaning = family.size() > 8 && family.substr(family.size() - 8) == " leaning";
    const bool levelled = family.size() > 9 && family.substr(family.size() - 9) == " levelled";
    if (!leaning && !levelled) continue;
    const auto o = pair.rfind("-o", pair.find("-kf"));  // NAME-SEED-gG-oOVERLAP-kf...
    ASSERT_NE(o, std::string::npos) << pair;
    if (std::stoi(pair.substr(o + 2)) < 30) continue;
    SCOPED_TRACE(pair);
    ASSERT_TRUE(row["success"].get<bool>()) << row.dump();
    if (!leaning) continue;
    const double grid = std::stod(family.substr(family.find(" g") + 2));
    EXPECT_LT(row["translation_error_m"].get<double>(), 2 * grid) << row.dump();
    EXPECT_LT(degrees(row["yaw_error_rad"].get<double>()), 0.5) << row.dump();
  }
  // The pose returned is the pose the decision judged, on every pair it
  // answers: the candidate it names, at the candidate's height; its 4-DoF
  // pose itself where the 6-DoF finish did not hold, else that pose
  // finished (moved by the finish alone, within its bound).
  int answers = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path / "matrix/results")) {
    const auto j = nlohmann::json::parse(std::ifstream(entry.path()));
    if (!j.value("reliable", false)) continue;
    SCOPED_TRACE(entry.path().filename().string());
    ++answers;
    const auto& answer = j["candidate_decision"]["answer"];
    ASSERT_FALSE(answer.is_null()) << j["candidate_decision"].dump();
    const auto& judged = j["candidates"].at(answer.get<size_t>());
    EXPECT_EQ(j["answered_by"], judged["from"]);
    EXPECT_EQ(j["height_offset_slices"], judged["refined"]["height_offset_slices"]);
    const auto& pose = j["T_target_source"];
    const auto& at = judged["refined"];
    if (!(j["finish"].is_object() && j["finish"].value("held", false))) {
      EXPECT_NEAR(pose["x"].get<double>(), at["x"].get<double>(), 1e-6);
      EXPECT_NEAR(pose["y"].get<double>(), at["y"].get<double>(), 1e-6);
      EXPECT_NEAR(std::remainder(pose["yaw"].get<double>() - at["yaw"].get<double>(), 2 * M_PI), 0.0, 1e-6);
    } else {
      EXPECT_LE(j["finish"]["moved_m"].get<double>(), 8 * j["grid"].get<double>()) << j["finish"].dump();
    }
  }
  int reliable = 0;
  for (const auto& [family, t] : got) reliable += t.right + t.wrong;
  EXPECT_EQ(answers, reliable) << "every answer's JSON was read";
}
