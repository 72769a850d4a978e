// One agreed-transform type: to JSON and back, to the wire and back.
#include <gtest/gtest.h>

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
  t.support = 30;
  t.runner_up_support = 18;
  t.inliers = 437;
  t.spread = {1.5, 2.0, 0.7};
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
}
