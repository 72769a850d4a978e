// One agreed-transform type: to JSON and back, to the wire and back.
#include <gtest/gtest.h>

#include <cmath>

#include "results/agreed_transform.hpp"
#include "transport/estimate_wire.hpp"

using namespace tomomap;

namespace {

AgreedTransform sample() {
  AgreedTransform t;
  t.target = "alpha";
  t.source = "bravo";
  t.target_version = 0x0123456789abcdefull;
  t.source_version = 42;
  t.reliable = true;
  t.T_target_source = {1.25, -2.5, 0.05, -3.0};
  t.answered_by = "search_pooled";
  t.lead_sigma = 7.25;
  t.computed_by = "bravo";
  t.computed_at_ms = 1763800000123;
  t.seconds = 0.75;
  return t;
}

void expectSame(const AgreedTransform& a, const AgreedTransform& b) { EXPECT_EQ(toJson(a), toJson(b)); }

}  // namespace

TEST(AgreedTransform, JsonRoundTrip) {
  const AgreedTransform t = sample();
  const nlohmann::json j = toJson(t);
  EXPECT_EQ(j["target_version"], "0123456789abcdef");
  EXPECT_DOUBLE_EQ(j["T_target_source"]["matrix"][0][3].get<double>(), 1.25);
  expectSame(agreedFromJson(j), t);

  AgreedTransform none = sample();
  none.reliable = false;
  none.reason = "only 2 slice pairs agree (need 3)";
  const nlohmann::json n = toJson(none);
  EXPECT_FALSE(n.contains("T_target_source")) << "no transform is stored for no match";
  EXPECT_EQ(agreedFromJson(n).reason, none.reason);

  nlohmann::json broken = j;
  broken.erase("quality");
  EXPECT_THROW(agreedFromJson(broken), InputError);
  broken = j;
  broken["target_version"] = "xyz";
  EXPECT_THROW(agreedFromJson(broken), InputError);

  broken = j;
  broken["quality"]["lead_sigma"] = -2.0;
  EXPECT_THROW(agreedFromJson(broken), InputError);
  broken = j;
  broken["quality"]["answered_by"] = "guesswork";
  EXPECT_THROW(agreedFromJson(broken), InputError);
  // A file of schema 2 weighed its pairs by slice pairs: read as the least clear.
  nlohmann::json schema2 = j;
  schema2["quality"] = {{"support", 30}, {"runner_up_support", 18}, {"inliers", 437}, {"inlier_spread", {1, 2, 0.7}}};
  EXPECT_EQ(agreedFromJson(schema2).lead_sigma, 0.0);

  // A file written before maps were levelled in the fleet: level maps, 4-DoF.
  nlohmann::json before = j;
  for (const char* key : {"target_up", "source_up", "T_target_source_6dof"}) before.erase(key);
  const AgreedTransform old = agreedFromJson(before);
  EXPECT_TRUE(old.ownFrames().isApprox(t.T_target_source.matrix(), 1e-12));
  EXPECT_EQ(old.source_up, Eigen::Vector3d::UnitZ());
}

TEST(AgreedTransform, ALevelledMapsUpTravelsAndTheWholeTransformUndoesIt) {
  AgreedTransform t = sample();
  // Bravo's map leaned 6 degrees about x and was levelled: its up in its own frame.
  const Eigen::AngleAxisd lean(radians(6), Eigen::Vector3d::UnitX());
  t.source_up = lean.inverse() * Eigen::Vector3d::UnitZ();
  const Eigen::Matrix4d whole = t.ownFrames();
  EXPECT_TRUE((whole.topLeftCorner<3, 3>() * t.source_up).isApprox(Eigen::Vector3d::UnitZ(), 1e-12))
      << "bravo's up is alpha's z";
  EXPECT_NEAR(whole(0, 3), 1.25, 1e-12) << "bravo's origin is where the levelled transform puts it";

  AgreedTransform back;
  ASSERT_FALSE(transport::fromWire(transport::toWire(t), back));
  EXPECT_TRUE(back.ownFrames().isApprox(whole, 1e-12));
  EXPECT_TRUE(back.source_up.isApprox(t.source_up, 1e-15));
  const AgreedTransform stored = agreedFromJson(toJson(t));
  EXPECT_TRUE(stored.ownFrames().isApprox(whole, 1e-12));
  expectSame(stored, t);

  // A forged estimate: an up beyond what any map is levelled by, a matrix that is not rigid.
  wire::TransformEstimate e = transport::toWire(t);
  e.source_up({0.0, 1.0, 0.0});
  EXPECT_EQ(transport::fromWire(e, back), transport::Reject::BadUp);
  e = transport::toWire(t);
  e.matrix()[0] = 2.0;
  EXPECT_EQ(transport::fromWire(e, back), transport::Reject::NotRigid);
  e.matrix()[5] = std::nan("");
  EXPECT_EQ(transport::fromWire(e, back), transport::Reject::NonFiniteTransform);
  nlohmann::json forged = toJson(t);
  forged["source_up"] = {0.0, 0.0, 2.0};
  EXPECT_THROW(agreedFromJson(forged), InputError);
}

TEST(AgreedTransform, WireRoundTripAndChecks) {
  const AgreedTransform t = sample();
  const wire::TransformEstimate e = transport::toWire(t);
  AgreedTransform back;
  ASSERT_FALSE(transport::fromWire(e, back));
  expectSame(back, t);

  wire::TransformEstimate swapped = e;
  swapped.target("charlie");
  EXPECT_EQ(transport::fromWire(swapped, back), transport::Reject::UnorderedPair);
  wire::TransformEstimate nan = e;
  nan.yaw(std::nan(""));
  EXPECT_EQ(transport::fromWire(nan, back), transport::Reject::NonFiniteTransform);
  // The pose graph weighs a pair by its lead: a forged one must not be.
  for (const double lead : {std::nan(""), -1.0, HUGE_VAL}) {
    wire::TransformEstimate forged = e;
    forged.lead_sigma(lead);
    EXPECT_EQ(transport::fromWire(forged, back), transport::Reject::BadQuality) << lead;
  }
  wire::TransformEstimate unknown = e;
  unknown.answered_by("guesswork");
  EXPECT_EQ(transport::fromWire(unknown, back), transport::Reject::BadQuality);
}
