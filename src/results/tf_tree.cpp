#include "tf_tree.hpp"

#include <set>

namespace tomomap {

std::vector<TreeEdge> spanningTree(const std::vector<AgreedTransform>& agreed, const std::string& root) {
  std::vector<TreeEdge> tree;
  std::set<std::string> in{root};
  // Prim: each round adds the most clearly singled-out link (lead_sigma) from the tree to a map not
  // in it yet. A fleet has tens of maps: the quadratic scan is nothing.
  for (;;) {
    const AgreedTransform* best = nullptr;
    bool target_inside = false;
    for (const auto& t : agreed) {
      if (!t.reliable) continue;
      const bool has_target = in.count(t.target) > 0, has_source = in.count(t.source) > 0;
      if (has_target == has_source) continue;  // both inside (a cycle) or both outside (not reachable yet)
      const std::string& outside = has_target ? t.source : t.target;
      if (!best || t.lead_sigma > best->lead_sigma ||
          (t.lead_sigma == best->lead_sigma && outside < (target_inside ? best->source : best->target))) {
        best = &t;
        target_inside = has_target;
      }
    }
    if (!best) return tree;
    TreeEdge e;
    e.stamp_ms = best->computed_at_ms;
    if (target_inside) {
      e.parent = best->target;
      e.child = best->source;
      e.T_parent_child = best->T_target_source;
      e.parent_up = best->target_up;
      e.child_up = best->source_up;
    } else {
      e.parent = best->source;
      e.child = best->target;
      e.T_parent_child = best->T_target_source.inverse();
      e.parent_up = best->source_up;
      e.child_up = best->target_up;
    }
    in.insert(e.child);
    tree.push_back(std::move(e));
  }
}

}  // namespace tomomap
