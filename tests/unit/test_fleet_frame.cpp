// The fleet's frame from pairwise transforms: poses in the reference's map,
// a wrong pair found by the loops it breaks and left out, pairs on no loop
// said to be unchecked.
#include <gtest/gtest.h>

#include <random>

#include "core/gravity.hpp"
#include "results/fleet_frame.hpp"

using namespace tomomap;

namespace {

/// Where each robot's map sits in the world (its origin and heading).
const std::map<std::string, Pose4> kWorld{{"alpha", {0, 0, 0, 0}},
                                          {"bravo", {6, 1, 0.2, 0.7}},
                                          {"charlie", {-3, 4, -0.1, -1.9}},
                                          {"delta", {2, -5, 0.4, 2.8}},
                                          {"echo", {9, 7, 0, -0.4}}};

/// The agreed transform of a pair as a good match gives it: the truth, off by
/// a few millimetres and a tenth of a degree.
AgreedTransform pair(const std::string& t, const std::string& s, std::mt19937& rng, double lead_sigma = 20) {
  std::normal_distribution<double> mm(0, 0.004), rad(0, 0.001);
  AgreedTransform a;
  a.target = t;
  a.source = s;
  a.reliable = true;
  a.lead_sigma = lead_sigma;
  a.T_target_source = kWorld.at(t).inverse() * kWorld.at(s);
  a.T_target_source.x += mm(rng);
  a.T_target_source.y += mm(rng);
  a.T_target_source.z += mm(rng);
  a.T_target_source.yaw += rad(rng);
  return a;
}

const std::vector<std::string> kFour{"alpha", "bravo", "charlie", "delta"};

/// Every pair among `agents`.
std::vector<AgreedTransform> allPairs(const std::vector<std::string>& agents, std::mt19937& rng) {
  std::vector<AgreedTransform> out;
  for (size_t i = 0; i < agents.size(); ++i)
    for (size_t j = i + 1; j < agents.size(); ++j) out.push_back(pair(agents[i], agents[j], rng));
  return out;
}

void expectPlacedRight(const FleetFrame& frame, const std::string& agent, double metres = 0.02) {
  const AgentPose* p = frame.pose(agent);
  ASSERT_NE(p, nullptr) << agent << " is not in the frame";
  const Pose4 truth = kWorld.at(frame.reference).inverse() * kWorld.at(agent);
  const PoseError e = poseError(p->T_reference_agent, truth);
  EXPECT_LT(e.translation, metres) << agent;
  EXPECT_LT(e.yaw, 0.005) << agent;
}

const CycleLimits kLimits{0.25, radians(10)};

}  // namespace

TEST(FleetFrame, EveryAgentIsPlacedInTheReferencesMapAndEveryPairOnALoopIsConsistent) {
  std::mt19937 rng(1);
  const FleetFrame frame = buildFleetFrame(allPairs(kFour, rng), kFour, "alpha", kLimits);
  ASSERT_TRUE(frame.converged);
  EXPECT_EQ(frame.optimised_pairs, 6u);
  ASSERT_EQ(frame.poses.size(), 4u);
  EXPECT_EQ(frame.poses.front().agent, "alpha");
  for (const auto& id : kFour) expectPlacedRight(frame, id);
  for (const auto& v : frame.pairs) {
    EXPECT_EQ(v.verdict, Consistency::Consistent) << pairText(v.pair);
    EXPECT_EQ(v.cycle.size(), 3u) << "closed over a third map";
    EXPECT_LT(v.cycle_translation, 0.06);
  }
  // Another reference: the same fleet seen from charlie's map.
  const FleetFrame from_charlie = buildFleetFrame(allPairs(kFour, rng), kFour, "charlie", kLimits);
  for (const auto& id : kFour) expectPlacedRight(from_charlie, id);
}

TEST(FleetFrame, OneWrongPairIsFlaggedInconsistentAndLeftOut) {
  std::mt19937 rng(2);
  // Each of the six pairs in turn matched a look-alike place: 1.5 m and 30
  // degrees off, once as clear as the others and once clearer
  // than any right pair.
  for (size_t wrong = 0; wrong < 6; ++wrong)
    for (const bool strongest : {false, true}) {
      auto pairs = allPairs(kFour, rng);
      pairs[wrong].T_target_source.x += 1.5;
      pairs[wrong].T_target_source.yaw += radians(30);
      if (strongest) pairs[wrong].lead_sigma = 60;
      const PairKey bad = pairs[wrong].pair();
      const FleetFrame frame = buildFleetFrame(pairs, kFour, "alpha", kLimits);
      const PairVerdict* v = frame.verdict(bad);
      ASSERT_NE(v, nullptr);
      EXPECT_EQ(v->verdict, Consistency::Inconsistent) << pairText(bad);
      EXPECT_GT(v->cycle_translation, 1.0);
      EXPECT_GT(degrees(v->cycle_yaw), 20.0);
      for (const auto& other : frame.pairs) {
        if (other.pair == bad) continue;
        EXPECT_EQ(other.verdict, Consistency::Consistent) << pairText(other.pair) << " with " << pairText(bad);
      }
      EXPECT_EQ(frame.optimised_pairs, 5u);
      for (const auto& id : kFour) expectPlacedRight(frame, id);
    }
}

TEST(FleetFrame, PairsOnNoLoopAreUncheckedAndAgentsWithoutAPathUnreachable) {
  std::mt19937 rng(3);
  // A chain alpha - bravo - charlie, and echo that overlaps nobody.
  const std::vector<AgreedTransform> chain{pair("alpha", "bravo", rng), pair("bravo", "charlie", rng)};
  const FleetFrame frame = buildFleetFrame(chain, {"alpha", "bravo", "charlie", "echo"}, "alpha", kLimits);
  for (const auto& v : frame.pairs) EXPECT_EQ(v.verdict, Consistency::Unchecked) << pairText(v.pair);
  expectPlacedRight(frame, "charlie");
  EXPECT_EQ(frame.pose("charlie")->path, (std::vector<std::string>{"alpha", "bravo", "charlie"}));
  EXPECT_EQ(frame.unreachable, std::vector<std::string>{"echo"});

  // Unreliable answers are no links.
  auto with_none = chain;
  AgreedTransform none = pair("alpha", "echo", rng);
  none.reliable = false;
  with_none.push_back(none);
  EXPECT_EQ(buildFleetFrame(with_none, {"alpha", "echo"}, "alpha", kLimits).unreachable,
            std::vector<std::string>{"echo"});
}

TEST(FleetFrame, ALoopOfThreeThatMissesPutsTheLeastClearPairAside) {
  // One loop cannot say which of its pairs is wrong: the weakest goes, and
  // the other two are left on no loop, unchecked.
  std::mt19937 rng(4);
  auto pairs = allPairs({"alpha", "bravo", "charlie"}, rng);
  pairs[2].T_target_source.x += 2.0;  // bravo<-charlie
  pairs[2].lead_sigma = 5;
  const FleetFrame frame = buildFleetFrame(pairs, {"alpha", "bravo", "charlie"}, "alpha", kLimits);
  EXPECT_EQ(frame.verdict({"bravo", "charlie"})->verdict, Consistency::Inconsistent);
  EXPECT_EQ(frame.verdict({"alpha", "bravo"})->verdict, Consistency::Unchecked);
  EXPECT_EQ(frame.verdict({"alpha", "charlie"})->verdict, Consistency::Unchecked);
  expectPlacedRight(frame, "charlie");
}

TEST(FleetFrame, EveryAgentComputesTheSameFrameWhateverOrderThePairsArriveIn) {
  // Five maps, every pair with noise: within a centimetre of the truth, and
  // the same to a nanometre from the pairs in reverse order.
  std::mt19937 rng(5);
  const std::vector<std::string> five{"alpha", "bravo", "charlie", "delta", "echo"};
  auto pairs = allPairs(five, rng);
  const FleetFrame frame = buildFleetFrame(pairs, five, "alpha", kLimits);
  for (const auto& id : five) expectPlacedRight(frame, id, 0.01);
  std::reverse(pairs.begin(), pairs.end());
  const FleetFrame again = buildFleetFrame(pairs, five, "alpha", kLimits);
  for (const auto& id : five) {
    const Pose4 a = frame.pose(id)->T_reference_agent, b = again.pose(id)->T_reference_agent;
    EXPECT_NEAR(a.x, b.x, 1e-9);
    EXPECT_NEAR(a.yaw, b.yaw, 1e-9);
  }
}

TEST(FleetFrame, JsonHasThePosesPathsAndVerdicts) {
  std::mt19937 rng(6);
  const nlohmann::json j = toJson(buildFleetFrame(allPairs(kFour, rng), kFour, "alpha", kLimits));
  EXPECT_EQ(j["reference"], "alpha");
  ASSERT_EQ(j["agents"].size(), 4u);
  EXPECT_TRUE(j["agents"][1]["T_reference_agent"].contains("matrix"));
  EXPECT_EQ(j["pairs"][0]["verdict"], "consistent");
  EXPECT_TRUE(j["pairs"][0]["cycle_error"].contains("translation_m"));
  EXPECT_EQ(j["optimised_pairs"], 6);
}

TEST(FleetFrame, AMapLevelledByAnotherUpSinceAnEarlierPairIsPlacedByItsNewestUp) {
  // Bravo's map leans 6 degrees as its SLAM saved it. Its first version was
  // levelled by an estimate 2 degrees off (alpha<-bravo, agreed then, kept);
  // its newest by the right up (bravo<-charlie).
  std::mt19937 rng(5);
  const Eigen::AngleAxisd lean(radians(6), Eigen::Vector3d(1, 2, 0).normalized());
  const Eigen::Vector3d up = lean * Eigen::Vector3d::UnitZ();  // bravo's up in its own frame
  const Eigen::Vector3d up_then = Eigen::AngleAxisd(radians(2), Eigen::Vector3d::UnitX()) * up;
  const Eigen::Matrix4d level_bravo = levelingMatrix(up);
  // The truth between own frames: alpha and charlie level, bravo leaning.
  const Eigen::Matrix4d alpha_bravo = (kWorld.at("alpha").inverse() * kWorld.at("bravo")).matrix() * level_bravo;
  const Eigen::Matrix4d bravo_charlie =
      level_bravo.inverse() * (kWorld.at("bravo").inverse() * kWorld.at("charlie")).matrix();

  AgreedTransform ab = pair("alpha", "bravo", rng), bc = pair("bravo", "charlie", rng),
                  ac = pair("alpha", "charlie", rng);
  ab.source_up = up_then;
  ab.T_target_source_6dof = alpha_bravo;
  ab.T_target_source = Pose4::fromMatrix(alpha_bravo * levelingMatrix(up_then).transpose());
  ab.computed_at_ms = 1;
  bc.target_up = up;
  bc.T_target_source_6dof = bravo_charlie;
  bc.computed_at_ms = 2;
  ac.computed_at_ms = 2;

  const FleetFrame frame = buildFleetFrame({ab, bc, ac}, {"alpha", "bravo", "charlie"}, "alpha", kLimits);
  const AgentPose* bravo = frame.pose("bravo");
  ASSERT_NE(bravo, nullptr);
  EXPECT_TRUE(bravo->up.isApprox(up, 1e-12)) << "the newest up";
  for (const auto& v : frame.pairs) EXPECT_EQ(v.verdict, Consistency::Consistent) << pairText(v.pair);
  const Eigen::Matrix4d placed = frame.ownFramePose(*bravo);
  const Eigen::Matrix3d turn = placed.topLeftCorner<3, 3>().transpose() * alpha_bravo.topLeftCorner<3, 3>();
  EXPECT_LT(degrees(Eigen::AngleAxisd(turn).angle()), 0.2) << placed << "\nexpected\n" << alpha_bravo;
  const Eigen::Vector4d far(8, 6, 2, 1);  // a point of bravo's map, metres from its origin
  EXPECT_LT((placed * far - alpha_bravo * far).norm(), 0.05);
}
