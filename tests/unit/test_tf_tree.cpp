// The fleet's maps as one tree of frames (results/tf_tree.hpp).
#include <gtest/gtest.h>

#include "results/tf_tree.hpp"

using namespace tomomap;

namespace {

AgreedTransform link(const std::string& target, const std::string& source, int lead, bool reliable = true) {
  AgreedTransform t;
  t.target = target;
  t.source = source;
  t.lead_sigma = lead;
  t.reliable = reliable;
  t.T_target_source = {1.0 * lead, 2.0, 0.5, 0.3};
  t.computed_at_ms = 1000u * static_cast<uint64_t>(lead);
  return t;
}

}  // namespace

TEST(TfTree, EachMapHangsFromTheTreeByItsClearestReliableLink) {
  const std::vector<AgreedTransform> agreed{link("a", "b", 10), link("b", "c", 20), link("a", "c", 5),
                                            link("a", "d", 40, /*reliable=*/false)};
  const auto tree = spanningTree(agreed, "a");
  ASSERT_EQ(tree.size(), 2u) << "d has no reliable link: left out";
  EXPECT_EQ(tree[0].parent, "a");
  EXPECT_EQ(tree[0].child, "b");
  EXPECT_EQ(tree[1].parent, "b") << "c through its 20-pair link, not a's 5";
  EXPECT_EQ(tree[1].child, "c");
  EXPECT_EQ(tree[1].T_parent_child.x, 20.0);
  EXPECT_EQ(tree[1].stamp_ms, 20000u);
}

TEST(TfTree, ALinkRunsFromSourceToTargetAsTheInverse) {
  const AgreedTransform bc = link("b", "c", 20);
  const auto tree = spanningTree({bc}, "c");
  ASSERT_EQ(tree.size(), 1u);
  EXPECT_EQ(tree[0].parent, "c");
  EXPECT_EQ(tree[0].child, "b");
  const Eigen::Matrix4d round_trip = tree[0].T_parent_child.matrix() * bc.T_target_source.matrix();
  EXPECT_TRUE(round_trip.isIdentity(1e-12)) << round_trip;
}

TEST(TfTree, ARootWithNoReliableLinkIsATreeOfNothing) {
  EXPECT_TRUE(spanningTree({link("a", "b", 10, false)}, "a").empty());
  EXPECT_TRUE(spanningTree({}, "a").empty());
}
